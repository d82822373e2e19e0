// The instruction-set extensions of the CPU the process runs on (and which of them are fast), for
// kernels that pick an AVX2, AVX-512 or carry-less-multiply clone at run time (compiled with target
// attributes, so the build's flags stay baseline). One place for the question, so that every kernel
// asks it the same way.
//
// Thread-safety: each answer is computed once (a function-local static) and then only read.
#pragma once

#include <fstream>
#include <string>

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

// True where AVX2's vgatherdps is the faster way to load 8 scattered floats: Intel cores that
// Linux reports as not affected by Gather Data Sampling (its microcode mitigation makes gathers
// several times slower on Skylake to Tiger Lake). Measured: on a Sapphire-Rapids-class Xeon,
// gathers took the screen AO pass from 5.2-5.4 to 4.8 ms (lantern-bench-cues --kernels); on AMD
// EPYCs they were slower than loads. False where it cannot be told (no such file: not Linux, or
// older).
inline bool cpu_prefers_gathers() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool yes = [] {
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_is("intel")) return false;
    std::ifstream in("/sys/devices/system/cpu/vulnerabilities/gather_data_sampling");
    std::string state;
    std::getline(in, state);
    return state == "Not affected";
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
