// The heap on transparent huge pages where the kernel gives them only on
// request (its "madvise" mode, Debian's default).
#pragma once

namespace rotafab::core {

// Large jobs touch gigabytes of fresh heap (a 50,000-face weave about
// 1.3 GB in its geometry alone), and on the virtual machines measured here
// each 4 KB page's first touch costs several microseconds: 3 s of the
// weave's 9. glibc backs its heap with huge pages when its tunable
// glibc.malloc.hugetlb is 1, and reads its tunables only as a program
// starts; so the program is started again at once, the same process (the
// same pid, arguments and descriptors), with that tunable added to
// GLIBC_TUNABLES. Nothing happens when GLIBC_TUNABLES already names it
// (the second start, or a person's own choice), under a tool that preloads
// a library (valgrind, heaptrack: valgrind would not follow the start), when
// the kernel's mode is not "madvise" (under "always" the heap has them
// already; under "never" it cannot), or when the start fails: the program
// goes on as it was.
// Call first thing in main(), before any thread starts.
void startAgainWithHugePageHeap(char** argv);

}  // namespace rotafab::core
