#include "localization/filter/odometry_noise.hpp"

namespace omniloc::filter {

const ParamList<OdometryNoiseParams>& OdometryNoiseParams::params(Keys keys) {
  using P = OdometryNoiseParams;
  static const ParamList<P> with_rot = {
      number_param("odo_trans_frac", &P::trans_frac, 0.0, 2.0, "", "motion noise: std of x and y per metre travelled (fraction)"),
      number_param("odo_rot_frac", &P::rot_frac, 0.0, 2.0, "", "motion noise: std of theta per radian turned (fraction)"),
      number_param("odo_rot_per_m", &P::rot_per_m, 0.0, 2.0, "rad/m", "motion noise: std of theta per metre travelled"),
      number_param("odo_floor_xy", &P::floor_xy, 0.0, 1.0, "m", "motion noise floor per frame in x and y"),
      number_param("odo_floor_theta", &P::floor_theta, 0.0, 1.0, "rad", "motion noise floor per frame in theta"),
  };
  static const ParamList<P> planar = {with_rot[0], with_rot[1], with_rot[3], with_rot[4]};
  return keys == Keys::WithRotPerMetre ? with_rot : planar;
}

OdometryNoiseParams OdometryNoiseParams::from_json(JsonReader& r, const OdometryNoiseParams& defaults, Keys keys) {
  OdometryNoiseParams p = defaults;
  read_params(r, p, params(keys));
  return p;
}

}  // namespace omniloc::filter
