#pragma once
// Source time functions. S(t) is dimensionless: the moment function M(t)/M0 of a moment-tensor
// source or F(t)/F0 of a body force. The solver injects the rate dS/dt (moment sources) or S
// (forces); the analytic solutions need S, dS/dt and d²S/dt², all closed-form here.
#include <string>

namespace panoptes::seismic {

/// A source time function S(t) with its first two derivatives.
struct SourceTimeFunction {
  enum class Kind {
    ricker,  ///< S = (1 − 2π²f0²τ²)·exp(−π²f0²τ²), τ = t − delay; peak 1 (transient: no net moment)
    kupper,  ///< dS/dt = (3π/4T)·sin³(πτ/T) on 0 ≤ τ ≤ T: S rises smoothly from 0 to 1 in T
    ramp,    ///< dS/dt = (1 − cos(2πτ/T))/T on 0 ≤ τ ≤ T: smoothed ramp from 0 to 1 in T
  };
  Kind kind = Kind::ricker;
  double frequency = 1.0;  ///< Ricker peak frequency f0 [Hz]
  double duration = 1.0;   ///< Küpper / ramp rise time T [s]
  double delay = 0.0;      ///< time shift [s]; Ricker default in make_ricker is 1.5/f0

  /// Ricker wavelet of peak frequency f0 centred at `delay` (negative delay → 1.5/f0).
  static SourceTimeFunction ricker(double f0, double delay = -1.0);
  /// Küpper rise (S from 0 to 1 over T) starting at delay.
  static SourceTimeFunction kupper(double T, double delay = 0.0);
  /// Smoothed ramp (S from 0 to 1 over T) starting at delay.
  static SourceTimeFunction ramp(double T, double delay = 0.0);
  /// Parses "ricker" | "kupper" | "ramp"; throws panoptes::Error otherwise.
  static Kind parse_kind(const std::string& name);
  static const char* kind_name(Kind k);

  double value(double t) const;   ///< S(t)
  double rate(double t) const;    ///< dS/dt [1/s]
  double rate2(double t) const;   ///< d²S/dt² [1/s²]
  /// Highest frequency with significant energy (2.5·f0 for Ricker, 2/T for Küpper and ramp): used
  /// for the points-per-wavelength check.
  double max_frequency() const;
  /// Time after which S is constant (end of the pulse).
  double end_time() const;
};

}  // namespace panoptes::seismic
