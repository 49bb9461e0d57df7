#include "sim/sensors.hpp"

#include <cmath>

namespace omniloc::sim {

OdometryNoise OdometryNoise::from_json(JsonReader& r, const OdometryNoise& d) {
  OdometryNoise n;
  n.trans_sigma = r.number("trans_sigma", d.trans_sigma, 0.0, 1.0);
  n.rot_sigma = r.number("rot_sigma", d.rot_sigma, 0.0, 1.0);
  n.rot_per_trans = r.number("rot_per_trans", d.rot_per_trans, 0.0, 1.0);
  n.scale_sigma = r.number("scale_sigma", d.scale_sigma, 0.0, 0.5);
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

HeadingNoise HeadingNoise::from_json(JsonReader& r, const HeadingNoise& d) {
  HeadingNoise n;
  n.noise_sigma = r.number("noise_sigma", d.noise_sigma, 0.0, 3.2);
  n.bias_walk = r.number("bias_walk", d.bias_walk, 0.0, 1.0);
  n.drift_rate = r.number("drift_rate", d.drift_rate, -1.0, 1.0);
  n.initial_bias = r.number("initial_bias", d.initial_bias, -kPi, kPi);
  n.offset = r.number("offset", d.offset, -kTwoPi, kTwoPi);
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
