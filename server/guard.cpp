#include "server/guard.h"

#include <pthread.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>

namespace costar::server {

namespace {

// Plain thread-locals (no constructor, no destructor): the signal handler reads them.
thread_local const char* t_role = nullptr;
thread_local std::uintptr_t t_stack_low = 0;  // the lowest address of the thread's stack

/// The alternate signal stack of one thread, with a guard page below it; freed when the thread
/// ends (if it is still the thread's alternate stack).
class AlternateStack {
 public:
  AlternateStack() {
    stack_t current{};
    if (::sigaltstack(nullptr, &current) == 0 && (current.ss_flags & SS_DISABLE) == 0) {
      return;  // the thread has one (a sanitizer's): keep it
    }
    const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    const auto wanted = std::max<long>(64 * 1024, 4 * ::sysconf(_SC_SIGSTKSZ));
    size_ = (static_cast<std::size_t>(wanted) + page - 1) / page * page + page;
    void* memory = ::mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_STACK, -1, 0);
    if (memory == MAP_FAILED) {
      return;
    }
    ::mprotect(memory, page, PROT_NONE);  // a handler that overflows this one faults, not corrupts
    stack_t stack{};
    stack.ss_sp = static_cast<char*>(memory) + page;
    stack.ss_size = size_ - page;
    if (::sigaltstack(&stack, nullptr) != 0) {
      ::munmap(memory, size_);
      return;
    }
    memory_ = memory;
    top_ = stack.ss_sp;
  }
  ~AlternateStack() {
    if (memory_ == nullptr) {
      return;
    }
    stack_t current{};
    if (::sigaltstack(nullptr, &current) != 0 || current.ss_sp != top_) {
      return;  // replaced since: not ours to free
    }
    stack_t off{};
    off.ss_flags = SS_DISABLE;
    ::sigaltstack(&off, nullptr);
    ::munmap(memory_, size_);
  }
  AlternateStack(const AlternateStack&) = delete;
  AlternateStack& operator=(const AlternateStack&) = delete;

 private:
  void* memory_ = nullptr;
  void* top_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace

void prepareServerThread(const char* role) noexcept {
  thread_local AlternateStack stack;
  t_role = role;
  pthread_attr_t attributes;
  if (::pthread_getattr_np(::pthread_self(), &attributes) == 0) {
    void* low = nullptr;
    std::size_t size = 0;
    if (::pthread_attr_getstack(&attributes, &low, &size) == 0) {
      t_stack_low = reinterpret_cast<std::uintptr_t>(low);
    }
    ::pthread_attr_destroy(&attributes);
  }
  if (::gettid() == ::getpid()) {
    return;  // the process's main thread keeps the process's name
  }
  char name[16];  // the kernel keeps 15 bytes
  std::snprintf(name, sizeof(name), "costar-%s", role);
  ::pthread_setname_np(::pthread_self(), name);
}

const char* serverThreadRole() noexcept { return t_role; }

bool nearStackLimit(const void* address) noexcept {
  constexpr std::uintptr_t kMargin = 64 * 1024;  // the guard page, and a frame that jumped over it
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  return t_stack_low != 0 && at + kMargin >= t_stack_low && at < t_stack_low + kMargin;
}

void logServerError(std::string_view where, std::string_view what) noexcept {
  try {
    spdlog::error("costar serve: {}: {}", where, what);
  } catch (...) {
    std::fputs("costar serve: an error that could not be logged\n", stderr);
  }
}

}  // namespace costar::server
