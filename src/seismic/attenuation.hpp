#pragma once
// Constant-Q over a band by a generalized Zener body (generalized Maxwell body in the Emmerich &
// Korn / Moczo & Kristek form): M(ω) = M_U·[1 − Σ_l Y_l·ω_l/(ω_l + iω)], relaxation frequencies
// ω_l log-spaced over the band, weights Y_l fitted by least squares so that
// Q⁻¹(ω) = Σ_l Y_l·(ω_l·ω + ω_l²·Q⁻¹)/(ω_l² + ω²) holds at 4·L log-spaced frequencies of the band.
#include <complex>
#include <vector>

namespace panoptes::seismic {

/// Relaxation frequencies and weights for one Q value.
struct ZenerFit {
  std::vector<double> omega;    ///< ω_l [rad/s]
  std::vector<double> weight;   ///< Y_l (dimensionless)
  /// M(ω)/M_U.
  std::complex<double> relative_modulus(double omega_eval) const;
  /// Q(ω) = Re M / Im M of the fitted body.
  double q(double omega_eval) const;
  /// M_U / (ρ·c²) such that the phase velocity at ω_ref equals c: Re(1/√(M/M_U))².
  double unrelaxed_factor(double omega_ref) const;
};

/// Fits L mechanisms to a constant Q over [fmin, fmax] Hz (Q = ∞ → all weights 0).
ZenerFit fit_constant_q(double q, double fmin, double fmax, int mechanisms);

}  // namespace panoptes::seismic
