#include "keyplace/features/descriptor.hpp"

#include <algorithm>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace keyplace {
namespace {

// FLIRTLib replaces empty bins by the smallest positive normal double before dividing.
constexpr double kPseudoZero = std::numeric_limits<double>::min();

// The terms of one sector, computed two at a time where SSE2 is there (every x86-64): the
// divisions are most of the distance's time, and a packed division costs about what a scalar
// one does. Each lane computes exactly the scalar Chi2Term below (the same max, subtraction,
// product and division, correctly rounded), and the caller adds the terms in order, so every
// distance is the scalar loop's bit for bit.
static_assert(kBetaGridRhoBins == 4, "SectorTerms handles sectors of four bins");
#if defined(__SSE2__)
inline void SectorTerms(const float* a, const float* b, double* terms) {
  // max(pseudo_zero, x) is std::max(x, pseudo_zero) for every x, NaN included (maxpd returns its
  // second operand when the comparison fails).
  const __m128d pseudo_zero = _mm_set1_pd(kPseudoZero);
  const __m128 a4 = _mm_loadu_ps(a);
  const __m128 b4 = _mm_loadu_ps(b);
  const __m128d q_low = _mm_max_pd(pseudo_zero, _mm_cvtps_pd(a4));
  const __m128d p_low = _mm_max_pd(pseudo_zero, _mm_cvtps_pd(b4));
  const __m128d q_high = _mm_max_pd(pseudo_zero, _mm_cvtps_pd(_mm_movehl_ps(a4, a4)));
  const __m128d p_high = _mm_max_pd(pseudo_zero, _mm_cvtps_pd(_mm_movehl_ps(b4, b4)));
  const __m128d diff_low = _mm_sub_pd(q_low, p_low);
  const __m128d diff_high = _mm_sub_pd(q_high, p_high);
  _mm_storeu_pd(terms, _mm_div_pd(_mm_mul_pd(diff_low, diff_low), _mm_add_pd(q_low, p_low)));
  _mm_storeu_pd(terms + 2,
                _mm_div_pd(_mm_mul_pd(diff_high, diff_high), _mm_add_pd(q_high, p_high)));
}
#else
// Histogram bins are >= 0 and a positive float exceeds kPseudoZero, so max() replaces exactly the
// zero bins. It compiles to a branch-free maxsd: the branch of `a == 0 ? z : a` mispredicted on
// the half-empty bins of real descriptors and made the distance 5x slower.
inline double Chi2Term(float a, float b) {
  const double q = std::max(static_cast<double>(a), kPseudoZero);
  const double p = std::max(static_cast<double>(b), kPseudoZero);
  const double diff = q - p;
  return diff * diff / (q + p);
}

inline void SectorTerms(const float* a, const float* b, double* terms) {
  for (int rho = 0; rho < kBetaGridRhoBins; ++rho) terms[rho] = Chi2Term(a[rho], b[rho]);
}
#endif

}  // namespace

double SymmetricChi2(const BetaGridDescriptor& a, const BetaGridDescriptor& b) {
  double sum = 0.0;
  double terms[kBetaGridRhoBins];
  for (int phi = 0; phi < kBetaGridPhiBins; ++phi) {
    const int base = phi * kBetaGridRhoBins;
    SectorTerms(a.data() + base, b.data() + base, terms);
    for (int rho = 0; rho < kBetaGridRhoBins; ++rho) sum += terms[rho];
  }
  return 0.5 * sum;
}

bool SymmetricChi2Below(const BetaGridDescriptor& a, const BetaGridDescriptor& b,
                        double threshold) {
  return SymmetricChi2IfBelow(a, b, threshold) < threshold;  // +inf when not below
}

double SymmetricChi2IfBelow(const BetaGridDescriptor& a, const BetaGridDescriptor& b,
                            double threshold) {
  // The sum of SymmetricChi2 in its order; partial sums never decrease (non-negative terms), so
  // stopping once the raw sum reaches twice the threshold rejects no pair below it.
  const double limit = 2.0 * threshold;
  double sum = 0.0;
  double terms[kBetaGridRhoBins];
  for (int phi = 0; phi < kBetaGridPhiBins; ++phi) {
    const int base = phi * kBetaGridRhoBins;
    SectorTerms(a.data() + base, b.data() + base, terms);
    for (int rho = 0; rho < kBetaGridRhoBins; ++rho) sum += terms[rho];
    if (sum >= limit) return std::numeric_limits<double>::infinity();
  }
  const double distance = 0.5 * sum;
  return distance < threshold ? distance : std::numeric_limits<double>::infinity();
}

}  // namespace keyplace
