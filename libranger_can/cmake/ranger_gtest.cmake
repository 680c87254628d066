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
