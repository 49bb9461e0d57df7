#include "sim/sensors.hpp"

#include <cmath>

namespace omniloc::sim {

const ParamList<OdometryNoise>& OdometryNoise::params() {
  using P = OdometryNoise;
  static const ParamList<P> list = {
      number_param("trans_sigma", &P::trans_sigma, 0.0, 1.0, "m/sqrt(m)", "random walk per square root of the distance travelled, along each robot axis"),
      number_param("rot_sigma", &P::rot_sigma, 0.0, 1.0, "rad/sqrt(rad)", "random walk per square root of the angle turned"),
      number_param("rot_per_trans", &P::rot_per_trans, 0.0, 1.0, "rad/sqrt(m)", "heading random walk from driving"),
      number_param("scale_sigma", &P::scale_sigma, 0.0, 0.5, "", "std of the per-run wheel scale error (0.01 = 1 %)"),
  };
  return list;
}

OdometryNoise OdometryNoise::from_json(JsonReader& r, const OdometryNoise& d) {
  OdometryNoise n = d;
  read_params(r, n, params());
  return n;
}

OdometrySensor::OdometrySensor(const OdometryNoise& noise, Rng rng) : noise_(noise), rng_(rng) {
  scale_x_ = 1.0 + rng_.normal(0.0, noise_.scale_sigma);
  scale_y_ = 1.0 + rng_.normal(0.0, noise_.scale_sigma);
  scale_r_ = 1.0 + rng_.normal(0.0, noise_.scale_sigma);
}

void OdometrySensor::accumulate(const Pose2& s) {
  const double d = std::hypot(s.x, s.y);
  const double a = std::fabs(s.theta);
  Pose2 noisy(s.x * scale_x_, s.y * scale_y_, s.theta * scale_r_);
  if (d > 0 || a > 0) {
    const double st = noise_.trans_sigma * std::sqrt(d);
    noisy.x += rng_.normal(0.0, 1.0) * st;
    noisy.y += rng_.normal(0.0, 1.0) * st;
    noisy.theta = wrap_angle(noisy.theta + rng_.normal(0.0, 1.0) * (noise_.rot_sigma * std::sqrt(a)) +
                             rng_.normal(0.0, 1.0) * (noise_.rot_per_trans * std::sqrt(d)));
  }
  acc_ = acc_.compose(noisy);
}

Odometry OdometrySensor::read(double t) {
  Odometry o;
  o.t = t;
  o.delta = acc_;
  acc_ = Pose2();
  return o;
}

const ParamList<HeadingNoise>& HeadingNoise::params() {
  using P = HeadingNoise;
  static const ParamList<P> list = {
      number_param("noise_sigma", &P::noise_sigma, 0.0, 3.2, "rad", "white noise per reading"),
      number_param("bias_walk", &P::bias_walk, 0.0, 1.0, "rad/sqrt(s)", "random-walk intensity of the bias"),
      number_param("drift_rate", &P::drift_rate, -1.0, 1.0, "rad/s", "deterministic drift"),
      number_param("initial_bias", &P::initial_bias, -kPi, kPi, "rad", "bias at the start"),
      number_param("offset", &P::offset, -kTwoPi, kTwoPi, "rad", "fixed mounting error"),
  };
  return list;
}

HeadingNoise HeadingNoise::from_json(JsonReader& r, const HeadingNoise& d) {
  HeadingNoise n = d;
  read_params(r, n, params());
  return n;
}

HeadingSensor::HeadingSensor(const HeadingNoise& noise, Rng rng) : noise_(noise), rng_(rng), bias_(noise.initial_bias) {}

void HeadingSensor::advance(double dt) {
  bias_ += noise_.drift_rate * dt;
  if (noise_.bias_walk > 0) bias_ += rng_.normal(0.0, noise_.bias_walk * std::sqrt(dt));
}

HeadingReading HeadingSensor::read(double t, double true_heading) {
  HeadingReading h;
  h.t = t;
  const double n = noise_.noise_sigma > 0 ? rng_.normal(0.0, noise_.noise_sigma) : 0.0;
  h.heading = wrap_angle(true_heading + noise_.offset + bias_ + n);
  return h;
}

}  // namespace omniloc::sim
