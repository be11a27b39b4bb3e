// Transparent huge pages for a process's allocations, where the system gives them on request.
#pragma once

namespace voxlab {

// Called first in main(). A run allocates tens to hundreds of MiB (llvmpipe keeps textures and
// buffers in host memory) and touches most of it once, so on a system whose transparent-huge-page
// policy is "madvise" (Debian's default) much of a short run is spent faulting in 4 KiB pages.
// glibc's malloc asks for huge pages only when started with the tunable glibc.malloc.hugetlb=1, so
// this re-runs the same command once with it: execv of /proc/self/exe, the arguments and the rest
// of the environment unchanged. It returns without doing so where that is not wanted or would not
// help: the tunable is already set (the re-run, or a caller's choice), VOXLAB_HUGE_PAGES=0, a
// sanitized build (its allocator is not glibc's), a policy other than "madvise", or a failed exec.
void restartWithHugePagesIfUseful(char** argv);

}  // namespace voxlab
