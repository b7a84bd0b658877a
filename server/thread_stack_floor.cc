// A floor under thread stack sizes that libraries ask for, for labelmeshd.
//
// glibc carves each thread's static thread-local storage out of its stack.
// labelmeshd links the core pipeline for its worker mode, and CGAL's 3D
// triangulations bring 96 KiB of thread-local storage with it; Debian's
// civetweb (which serves /metrics) asks for 100 KiB stacks, and
// pthread_create refuses those with EINVAL: 96 KiB of TLS plus the guard
// page and glibc's minimum leave such a stack too small. This definition
// takes the place of libc's for every caller in the process and raises
// requests below 1 MiB to 1 MiB (so a request below PTHREAD_STACK_MIN also
// succeeds now); larger requests pass through unchanged.
#include <dlfcn.h>
#include <pthread.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstdlib>

namespace {

constexpr size_t kMinimumStackBytes = size_t{1} << 20;

using SetStackSize = int (*)(pthread_attr_t*, size_t);

SetStackSize libc_set_stack_size() {
  static const auto function = [] {
    auto found = reinterpret_cast<SetStackSize>(dlsym(RTLD_NEXT, "pthread_attr_setstacksize"));
    if (found == nullptr) {
      std::fputs("labelmeshd: libc's pthread_attr_setstacksize not found\n", stderr);
      std::abort();
    }
    return found;
  }();
  return function;
}

}  // namespace

extern "C" int pthread_attr_setstacksize(pthread_attr_t* attr, size_t size) noexcept {
  return libc_set_stack_size()(attr, std::max(size, kMinimumStackBytes));
}
