#include "localization/filter/odometry_noise.hpp"

namespace omniloc::filter {

OdometryNoiseParams OdometryNoiseParams::from_json(JsonReader& r, const OdometryNoiseParams& defaults, Keys keys) {
  OdometryNoiseParams p = defaults;
  p.trans_frac = r.number("odo_trans_frac", p.trans_frac, 0.0, 2.0);
  p.rot_frac = r.number("odo_rot_frac", p.rot_frac, 0.0, 2.0);
  if (keys == Keys::WithRotPerMetre) p.rot_per_m = r.number("odo_rot_per_m", p.rot_per_m, 0.0, 2.0);
  p.floor_xy = r.number("odo_floor_xy", p.floor_xy, 0.0, 1.0);
  p.floor_theta = r.number("odo_floor_theta", p.floor_theta, 0.0, 1.0);
  return p;
}

}  // namespace omniloc::filter
