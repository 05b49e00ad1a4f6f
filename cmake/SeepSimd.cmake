# Vector width of the build (SEEP_SIMD) and the floating-point rules that keep every width's
# results the same bits.
#
# The coupled step's passes (edge turns and lenses, apertures, the explicit sweep) divide and take
# square roots per contact: with 4 doubles a vector instead of SSE2's 2 they run 10-25 % faster
# (docs/architecture.md §5.2). Results do not depend on the width: IEEE add, multiply, divide and sqrt
# are correctly rounded per element, the vectoriser reorders no sum (no -ffast-math, no
# -fassociative-math), and AVX2 here comes without FMA, whose fused a*b+c rounds once where the
# SSE2 build rounds twice. -ffp-contract=off says the same to the compiler for any flags a user
# adds (-march=native brings FMA): no a*b+c is ever fused behind the source's back. The twelve
# examples' final-state hashes are equal from an SSE2 and an AVX2 build (seep_example_states).
#
#   SEEP_SIMD=auto  AVX2 when the machine that configures can run it (the binaries are for this
#                   machine, as a -march=native build's are), else SSE2
#   SEEP_SIMD=avx2  AVX2 whatever the build machine (for a cluster whose nodes all have it)
#   SEEP_SIMD=sse2  the x86-64 baseline: runs on any x86-64
include(CheckCXXSourceRuns)

set(SEEP_SIMD "auto" CACHE STRING "Vector width of the build: auto, avx2 or sse2")
set_property(CACHE SEEP_SIMD PROPERTY STRINGS auto avx2 sse2)

add_compile_options(-ffp-contract=off)

set(seep_simd_choice "${SEEP_SIMD}")
if(seep_simd_choice STREQUAL "auto")
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
    check_cxx_source_runs("int main() { return __builtin_cpu_supports(\"avx2\") ? 0 : 1; }"
                          SEEP_HOST_RUNS_AVX2)
  endif()
  if(SEEP_HOST_RUNS_AVX2)
    set(seep_simd_choice avx2)
  else()
    set(seep_simd_choice sse2)
  endif()
endif()

if(seep_simd_choice STREQUAL "avx2")
  # -mavx2 alone: no -mfma (see above), so Eigen and the vectoriser multiply and add separately.
  add_compile_options(-mavx2)
elseif(NOT seep_simd_choice STREQUAL "sse2")
  message(FATAL_ERROR "SEEP_SIMD: '${SEEP_SIMD}' is not one of auto, avx2, sse2")
endif()
message(STATUS "seep: SIMD ${seep_simd_choice} (SEEP_SIMD=${SEEP_SIMD}), -ffp-contract=off")
