# GoogleTest for the test suites, the same on every CMake from 3.16 on:
#  * RANGER_GTEST / RANGER_GTEST_MAIN: the targets to link (GTest::gtest and GTest::gtest_main
#    where CMake >= 3.20 or GoogleTest's own package configuration provides them, GTest::GTest and
#    GTest::Main from the FindGTest of older CMake);
#  * ranger_discover_tests(TARGET [PROPERTIES ...]): gtest_discover_tests, listing the cases when
#    the tests run (DISCOVERY_MODE PRE_TEST, CMake >= 3.18) where CMake can, after the build before.
find_package(GTest)
include(GoogleTest)
if(TARGET GTest::gtest_main)
  set(RANGER_GTEST GTest::gtest)
  set(RANGER_GTEST_MAIN GTest::gtest_main)
else()
  set(RANGER_GTEST GTest::GTest)
  set(RANGER_GTEST_MAIN GTest::Main)
endif()
function(ranger_discover_tests target)
  set(mode)
  if(NOT CMAKE_VERSION VERSION_LESS 3.18)
    set(mode DISCOVERY_MODE PRE_TEST)
  endif()
  gtest_discover_tests(${target} ${mode} DISCOVERY_TIMEOUT 60 ${ARGN})
endfunction()

# ranger_test_threads(TARGET THREADED): the test executable TARGET and ThreadSanitizer. THREADED
# (a boolean) says the suite starts threads: its cases carry the CTest label `threads` (set by the
# caller, with RANGER_TEST_THREADS=1 in their environment) and the target joins
# `ranger_threaded_tests`, which the TSan build builds (scripts/test_sanitizers.sh). In the plain
# build every test executable links the thread guard (test/thread_guard/), which fails a suite
# that starts a thread without the label.
set(RANGER_THREAD_GUARD_SOURCE ${CMAKE_CURRENT_LIST_DIR}/../test/thread_guard/thread_guard.cpp)
function(ranger_test_threads target threaded)
  if(NOT TARGET ranger_threaded_tests)
    add_custom_target(ranger_threaded_tests)
  endif()
  if(threaded)
    add_dependencies(ranger_threaded_tests ${target})
  endif()
  if("${RANGER_SANITIZE}" STREQUAL "")
    if(NOT TARGET ranger_thread_guard)
      add_library(ranger_thread_guard OBJECT ${RANGER_THREAD_GUARD_SOURCE})
      target_link_libraries(ranger_thread_guard PRIVATE ${RANGER_GTEST})
    endif()
    target_link_libraries(${target} PRIVATE ranger_thread_guard ${CMAKE_DL_LIBS})
  endif()
endfunction()
