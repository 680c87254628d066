// Which test suites start threads, checked (issue 34): ThreadSanitizer runs only the suites with
// the CTest label `threads` (scripts/test_sanitizers.sh), so a suite that starts a thread without
// the label would escape it. Linked into every test executable of the plain build (not of the
// sanitizer builds, whose runtimes intercept pthread_create themselves), this file interposes
// pthread_create (the executable's definition comes first in the dynamic linker's search, so
// std::thread in libstdc++ reaches it) to note that a thread was started, and a global test
// environment fails the run at its end when one was and the suite is not labelled: CTest gives
// labelled suites RANGER_TEST_THREADS=1 (ranger_gtest.cmake).
#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

namespace {

std::atomic<bool> g_thread_started{false};

using CreateFn = int (*)(pthread_t*, const pthread_attr_t*, void* (*)(void*), void*);

class ThreadLabelCheck final : public testing::Environment {
 public:
  void TearDown() override {
    const char* labelled = std::getenv("RANGER_TEST_THREADS");
    const bool threads = labelled != nullptr && std::strcmp(labelled, "1") == 0;
    if (g_thread_started.load() && !threads) {
      ADD_FAILURE() << "this suite starts a thread but does not carry the CTest label `threads`: "
                       "ThreadSanitizer would not run it (list it in RANGER_THREADED_TESTS in "
                       "libranger_can/CMakeLists.txt, or give it LABEL threads in tests/)";
    }
  }
};

// gtest takes ownership of the environment (its documented interface).
[[maybe_unused]] testing::Environment* const g_check =
    testing::AddGlobalTestEnvironment(new ThreadLabelCheck);

}  // namespace

extern "C" int pthread_create(pthread_t* thread, const pthread_attr_t* attr, void* (*start)(void*),
                              void* arg) noexcept {
  static const auto real = reinterpret_cast<CreateFn>(::dlsym(RTLD_NEXT, "pthread_create"));
  g_thread_started.store(true);
  return real(thread, attr, start, arg);
}
