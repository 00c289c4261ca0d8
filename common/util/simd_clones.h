#ifndef MBSLAM_COMMON_UTIL_SIMD_CLONES_H_
#define MBSLAM_COMMON_UTIL_SIMD_CLONES_H_

// MBSLAM_SIMD_CLONES before a function definition: on x86-64, clones for AVX-512 (GCC)
// and AVX2 next to the baseline one, glibc picking the best at load time. Only for
// functions whose loops give the same bits either way (element-wise float arithmetic
// without reordered reductions, or exact integer arithmetic). GCC's AVX-512 target
// brings FMA with it, and a fused multiply-add rounds once where the baseline rounds
// twice: contraction is off in the clones, so that every clone computes the same
// products and sums. (Clang: AVX2 only, which has no FMA; its per-expression contraction
// would otherwise fuse.) Elsewhere (ARM: NEON is the baseline there), and under the
// sanitizers (whose runtime is not up when the loader picks), one build.

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
#define MBSLAM_SIMD_NO_CLONES
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define MBSLAM_SIMD_NO_CLONES
#endif
#if defined(__x86_64__) && defined(__clang__) && !defined(MBSLAM_SIMD_NO_CLONES)
#define MBSLAM_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#elif defined(__x86_64__) && defined(__GNUC__) && !defined(MBSLAM_SIMD_NO_CLONES)
#define MBSLAM_SIMD_CLONES \
  __attribute__((target_clones("avx512f", "avx2", "default"), optimize("fp-contract=off")))
#else
#define MBSLAM_SIMD_CLONES
#endif

#endif  // MBSLAM_COMMON_UTIL_SIMD_CLONES_H_
