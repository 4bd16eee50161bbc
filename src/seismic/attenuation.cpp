#include "seismic/attenuation.hpp"

#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace panoptes::seismic {

std::complex<double> ZenerFit::relative_modulus(double w) const {
  std::complex<double> m = 1.0;
  for (std::size_t l = 0; l < omega.size(); ++l) m -= weight[l] * omega[l] / std::complex<double>(omega[l], w);
  return m;
}

double ZenerFit::q(double w) const {
  const auto m = relative_modulus(w);
  return m.real() / m.imag();
}

double ZenerFit::unrelaxed_factor(double w) const {
  const auto m = relative_modulus(w);
  const double r = (1.0 / std::sqrt(m)).real();
  return r * r;
}

ZenerFit fit_constant_q(double q, double fmin, double fmax, int L) {
  require(L >= 1, "attenuation: at least one relaxation mechanism is needed");
  require(fmin > 0 && fmax > fmin, "attenuation band [" + std::to_string(fmin) + ", " + std::to_string(fmax) +
                                       "] Hz is invalid (need 0 < fmin < fmax)");
  require(q > 0, "Q must be > 0, got " + std::to_string(q));
  ZenerFit fit;
  const double two_pi = 2 * std::numbers::pi;
  for (int l = 0; l < L; ++l) {
    const double f = L == 1 ? std::sqrt(fmin * fmax) : fmin * std::pow(fmax / fmin, double(l) / (L - 1));
    fit.omega.push_back(two_pi * f);
  }
  fit.weight.assign(L, 0.0);
  if (!std::isfinite(q)) return fit;
  const double qi = 1.0 / q;
  // Least squares over K frequencies: A·Y = b with A_kl = (ω_l ω_k + ω_l² Q⁻¹)/(ω_l² + ω_k²), b_k = Q⁻¹.
  const int K = 4 * L;
  std::vector<double> ata(L * L, 0.0), atb(L, 0.0);
  for (int k = 0; k < K; ++k) {
    const double w = two_pi * fmin * std::pow(fmax / fmin, double(k) / (K - 1));
    std::vector<double> row(L);
    for (int l = 0; l < L; ++l) {
      const double wl = fit.omega[l];
      row[l] = (wl * w + wl * wl * qi) / (wl * wl + w * w);
    }
    for (int a = 0; a < L; ++a) {
      atb[a] += row[a] * qi;
      for (int c = 0; c < L; ++c) ata[a * L + c] += row[a] * row[c];
    }
  }
  // Gaussian elimination with partial pivoting on the small normal system.
  std::vector<double>& y = fit.weight;
  for (int c = 0; c < L; ++c) {
    int p = c;
    for (int r = c + 1; r < L; ++r)
      if (std::abs(ata[r * L + c]) > std::abs(ata[p * L + c])) p = r;
    for (int k = 0; k < L; ++k) std::swap(ata[c * L + k], ata[p * L + k]);
    std::swap(atb[c], atb[p]);
    for (int r = c + 1; r < L; ++r) {
      const double f = ata[r * L + c] / ata[c * L + c];
      for (int k = c; k < L; ++k) ata[r * L + k] -= f * ata[c * L + k];
      atb[r] -= f * atb[c];
    }
  }
  for (int r = L - 1; r >= 0; --r) {
    double s = atb[r];
    for (int k = r + 1; k < L; ++k) s -= ata[r * L + k] * y[k];
    y[r] = s / ata[r * L + r];
  }
  return fit;
}

}  // namespace panoptes::seismic
