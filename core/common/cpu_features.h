// The instruction-set extensions of the CPU the process runs on, for kernels that pick an AVX2,
// AVX-512 or carry-less-multiply clone at run time (compiled with target attributes, so the build's
// flags stay baseline). One place for the question, so that every kernel asks it the same way.
//
// Thread-safety: each answer is computed once (a function-local static) and then only read.
#pragma once

namespace lantern {

// True where the CPU has AVX2 (always false off x86-64 or without GCC/Clang builtins).
inline bool cpu_has_avx2() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool yes = [] {
    __builtin_cpu_init();  // safe before main(): a static initialiser may ask
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return yes;
#else
  return false;
#endif
}

// True where the CPU has carry-less multiplication (PCLMULQDQ) and SSE4.1.
inline bool cpu_has_pclmul() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("sse4.1");
  }();
  return yes;
#else
  return false;
#endif
}

// True where the CPU has AVX-512 F, VL, DQ and BW (the set the 512-bit kernels are built for).
inline bool cpu_has_avx512_bw() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
  }();
  return yes;
#else
  return false;
#endif
}

}  // namespace lantern
