#pragma once
// The FLIRT beta-grid descriptor and its symmetric chi-squared distance.

#include <array>

namespace keyplace {

constexpr int kBetaGridPhiBins = 12;  // angular sectors of 30 deg, relative to the keypoint
constexpr int kBetaGridRhoBins = 4;   // rings between 0.02 m and 0.5 m
constexpr int kBetaGridBins = kBetaGridPhiBins * kBetaGridRhoBins;

/// Beta-grid histogram, flattened phi-major: index = phi * kBetaGridRhoBins + rho. Phi bin k
/// spans [-pi + k*30deg, -pi + (k+1)*30deg) relative to the keypoint orientation; rho bin r spans
/// [0.02 + 0.12 r, 0.02 + 0.12 (r+1)] m. The values sum to 1.
using BetaGridDescriptor = std::array<float, kBetaGridBins>;

/// FLIRTLib's symmetric chi-squared distance: sum over bins of 0.5 (q - p)^2 / (q + p), where a
/// zero bin is replaced by the smallest positive normal double (FLIRTLib's PSEUDOZERO). Lies in
/// [0, 1] for normalised histograms; 0 for identical ones. Bins must be >= 0 (histograms).
double SymmetricChi2(const BetaGridDescriptor& a, const BetaGridDescriptor& b);

/// SymmetricChi2(a, b) < threshold, but stops summing as soon as the partial sum reaches the
/// threshold (all terms are non-negative). For hot matching loops.
bool SymmetricChi2Below(const BetaGridDescriptor& a, const BetaGridDescriptor& b, double threshold);

/// SymmetricChi2(a, b), bit for bit, when SymmetricChi2Below(a, b, threshold); otherwise +inf,
/// with the same early stop. One pass where a pair needs both the test and the distance.
double SymmetricChi2IfBelow(const BetaGridDescriptor& a, const BetaGridDescriptor& b,
                            double threshold);

}  // namespace keyplace
