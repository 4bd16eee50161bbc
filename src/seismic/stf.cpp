#include "seismic/stf.hpp"

#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace panoptes::seismic {

namespace {
constexpr double pi = std::numbers::pi;
}

SourceTimeFunction SourceTimeFunction::ricker(double f0, double delay) {
  require(f0 > 0 && std::isfinite(f0), "Ricker peak frequency must be > 0, got " + std::to_string(f0));
  SourceTimeFunction s;
  s.kind = Kind::ricker;
  s.frequency = f0;
  s.delay = delay < 0 ? 1.5 / f0 : delay;
  return s;
}

SourceTimeFunction SourceTimeFunction::kupper(double T, double delay) {
  require(T > 0 && std::isfinite(T), "Kupper duration must be > 0, got " + std::to_string(T));
  SourceTimeFunction s;
  s.kind = Kind::kupper;
  s.duration = T;
  s.delay = delay;
  return s;
}

SourceTimeFunction SourceTimeFunction::ramp(double T, double delay) {
  require(T > 0 && std::isfinite(T), "ramp duration must be > 0, got " + std::to_string(T));
  SourceTimeFunction s;
  s.kind = Kind::ramp;
  s.duration = T;
  s.delay = delay;
  return s;
}

SourceTimeFunction::Kind SourceTimeFunction::parse_kind(const std::string& name) {
  if (name == "ricker") return Kind::ricker;
  if (name == "kupper") return Kind::kupper;
  if (name == "ramp") return Kind::ramp;
  throw Error("unknown source time function '" + name + "' (expected ricker, kupper or ramp)");
}

const char* SourceTimeFunction::kind_name(Kind k) {
  switch (k) {
    case Kind::ricker: return "ricker";
    case Kind::kupper: return "kupper";
    case Kind::ramp: return "ramp";
  }
  return "?";
}

double SourceTimeFunction::value(double t) const {
  const double tau = t - delay;
  switch (kind) {
    case Kind::ricker: {
      const double a = pi * pi * frequency * frequency * tau * tau;
      return (1 - 2 * a) * std::exp(-a);
    }
    case Kind::kupper: {
      if (tau <= 0) return 0;
      if (tau >= duration) return 1;
      // ∫ sin³ = −cos + cos³/3; normalised by 4/3.
      const double c = std::cos(pi * tau / duration);
      return 0.75 * ((1 - c) - (1 - c * c * c) / 3.0);
    }
    case Kind::ramp: {
      if (tau <= 0) return 0;
      if (tau >= duration) return 1;
      return tau / duration - std::sin(2 * pi * tau / duration) / (2 * pi);
    }
  }
  return 0;
}

double SourceTimeFunction::rate(double t) const {
  const double tau = t - delay;
  switch (kind) {
    case Kind::ricker: {
      const double b = pi * pi * frequency * frequency;
      const double a = b * tau * tau;
      return 2 * b * tau * (2 * a - 3) * std::exp(-a);
    }
    case Kind::kupper: {
      if (tau <= 0 || tau >= duration) return 0;
      const double s = std::sin(pi * tau / duration);
      return 0.75 * pi / duration * s * s * s;
    }
    case Kind::ramp: {
      if (tau <= 0 || tau >= duration) return 0;
      return (1 - std::cos(2 * pi * tau / duration)) / duration;
    }
  }
  return 0;
}

double SourceTimeFunction::rate2(double t) const {
  const double tau = t - delay;
  switch (kind) {
    case Kind::ricker: {
      const double b = pi * pi * frequency * frequency;
      const double a = b * tau * tau;
      // d/dt [2bτ(2a−3)e^{−a}] with da/dτ = 2bτ.
      return 2 * b * std::exp(-a) * ((2 * a - 3) + tau * 4 * b * tau - (2 * a - 3) * 2 * a);
    }
    case Kind::kupper: {
      if (tau <= 0 || tau >= duration) return 0;
      const double w = pi / duration;
      const double s = std::sin(w * tau);
      return 0.75 * w * 3 * s * s * std::cos(w * tau) * w;
    }
    case Kind::ramp: {
      if (tau <= 0 || tau >= duration) return 0;
      const double w = 2 * pi / duration;
      return w * std::sin(w * tau) / duration;
    }
  }
  return 0;
}

double SourceTimeFunction::max_frequency() const {
  return kind == Kind::ricker ? 2.5 * frequency : 2.0 / duration;
}

double SourceTimeFunction::end_time() const {
  return kind == Kind::ricker ? delay + 1.5 / frequency : delay + duration;
}

}  // namespace panoptes::seismic
