/* Private to the core's sources: TF_SIZED marks a small function that must be inlined, so that a
 * size or count passed to it as a constant at the call site unrolls its loops (dopri5.c's and rodas4.c's step
 * functions, sensitivity.c's J S product, plant.c's fast right-hand side). */
#ifndef THERMOFRICTION_INLINE_H
#define THERMOFRICTION_INLINE_H
#if defined(__GNUC__) || defined(__clang__)
#define TF_SIZED static inline __attribute__((always_inline))
#else
#define TF_SIZED static inline
#endif
#endif
