#include "app/huge_pages.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define VOXLAB_SANITIZED_ALLOCATOR 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define VOXLAB_SANITIZED_ALLOCATOR 1
#endif

namespace voxlab {

static constexpr const char* kHugePageTunable = "glibc.malloc.hugetlb=1";

void restartWithHugePagesIfUseful(char** argv) {
#ifdef VOXLAB_SANITIZED_ALLOCATOR
  (void)argv;
  return;
#else
  const char* choice = std::getenv("VOXLAB_HUGE_PAGES");
  if (choice && std::string(choice) == "0") return;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string current = tunables ? tunables : "";
  if (current.find("glibc.malloc.hugetlb") != std::string::npos) return;
  std::ifstream policy("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(policy)), std::istreambuf_iterator<char>());
  if (modes.find("[madvise]") == std::string::npos) return;
  const std::string extended = current.empty() ? kHugePageTunable : current + ":" + kHugePageTunable;
  if (setenv("GLIBC_TUNABLES", extended.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Not restarted (no /proc, say): go on as started, without the tunable in the environment that
  // child processes (bench's timed runs) inherit.
  if (tunables) setenv("GLIBC_TUNABLES", tunables, 1);
  else unsetenv("GLIBC_TUNABLES");
#endif
}

}  // namespace voxlab
