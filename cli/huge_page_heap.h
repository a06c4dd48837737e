#pragma once
// A level's bake reads arrays of hundreds of MiB at random (form-factor rows, element arrays, the BVHs): with the
// heap in 4 KiB pages most of those reads also miss the TLB, and more so the larger the level. glibc (2.35 and
// later) backs its heap with transparent huge pages only when told so at start-up, by the environment
// (GLIBC_TUNABLES=glibc.malloc.hugetlb=1), and then only its main heap: the arenas it opens for other threads stay in
// 4 KiB pages, so one arena serves every thread (glibc.malloc.arena_max=1). The baker sets both and runs itself
// again, once, before anything else. Measured on the 10-copy tiled level: about 5 % less time (three bakes against
// two), 2 % more peak memory (docs/performance.md, session 36). The one arena, on 30 copies: 1,402 → 1,271 s, 100 MiB
// less at peak, the same texels (session 41).
namespace hemibake::cli {

// Unless GLIBC_TUNABLES already names glibc.malloc.hugetlb (the user's choice, kept: =0 turns this off) or the
// kernel has transparent huge pages off: adds glibc.malloc.hugetlb=1 to GLIBC_TUNABLES, and glibc.malloc.arena_max=1
// unless the user set that one, and re-executes this program
// (/proc/self/exe) with the same arguments. Returns only if it did not (nothing to do, or the exec failed: the run
// goes on in 4 KiB pages, as before). Call first in main, before any thread starts.
void restartWithHugePageHeap(char** argv);

}  // namespace hemibake::cli
