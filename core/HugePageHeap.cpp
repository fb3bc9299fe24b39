#include "core/HugePageHeap.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

namespace rotafab::core {

void startAgainWithHugePageHeap(char** argv) {
#ifdef __GLIBC__
  constexpr const char* kTunable = "glibc.malloc.hugetlb";
  const char* set = std::getenv("GLIBC_TUNABLES");
  const std::string tunables = set ? set : "";
  if (tunables.find(kTunable) != std::string::npos) return;
  // Under a tool that preloads itself (valgrind, heaptrack), the program as it was started.
  if (const char* preload = std::getenv("LD_PRELOAD"); preload && *preload) return;
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(mode)), std::istreambuf_iterator<char>());
  if (modes.find("[madvise]") == std::string::npos) return;
  const std::string value = (tunables.empty() ? "" : tunables + ":") + kTunable + "=1";
  if (::setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);
  // Not started again: as before.
  if (set) {
    ::setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
  } else {
    ::unsetenv("GLIBC_TUNABLES");
  }
#else
  (void)argv;
#endif
}

}  // namespace rotafab::core
