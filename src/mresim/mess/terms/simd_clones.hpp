#pragma once

// MRESIM_SIMD_CLONES before a function compiles it once per instruction set (AVX-512, AVX2 and
// the x86-64 baseline) and lets the loader pick the widest the processor has (GCC's function
// multi-versioning); elsewhere it is empty and the function is compiled once. The files that
// use it are built without contraction into fused multiply-adds and without errno from sqrt
// (CMakeLists.txt), so that every clone rounds as the scalar code does.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define MRESIM_SIMD_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define MRESIM_SIMD_CLONES
#endif
