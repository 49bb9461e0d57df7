// Dead reckoning over olp/1 in C++: the start pose composed with every frame's odometry
// (with params {"wants_image": true} it also takes the image and reports its mean in frames.csv).
// Its est.tum equals omniloc's built-in odometry_only on the same scenario and seed (to the bit:
// compose_odometry does Pose2::compose's operations in the same order). Built by CMake as
// build/olp_cpp_example; use it as
//   "localizer": {"type": "external", "command": ["build/olp_cpp_example"]}
#include <cstdio>
#include <iostream>

#include "omniloc_client.hpp"

namespace olp = omniloc_client;

class DeadReckoning : public olp::Localizer {
 public:
  DeadReckoning() {
    name = "cpp_dead_reckoning";
    version = "1.0";
    needs_start_pose = true;
  }
  void ready(const olp::Hello& h) override {
    // {"params": {"wants_image": true}}: the image comes along (only summarised here, as a demo)
    wants_image = h.params.value("wants_image", false);
    std::cerr << "cpp_dead_reckoning: robot " << h.robot << " on " << h.field.name << ", " << h.camera_rate_hz << " Hz\n";
  }
  void reset(std::uint64_t, const std::optional<olp::Pose>& start) override { pose_ = start.value_or(olp::Pose{}); }
  olp::Estimate update(const olp::Frame& f) override {
    pose_ = olp::compose_odometry(pose_, f.odometry);
    if (f.k % 300 == 0) std::printf("frame %lld\n", f.k);  // lands in stderr: serve() keeps stdout for the protocol
    olp::Estimate e;
    e.pose = pose_;
    e.mode = "dead_reckoning";
    e.extra["n_line_points"] = static_cast<double>(f.line_points.size());
    if (!f.image.empty()) {
      double sum = 0;
      for (std::uint8_t b : f.image) sum += b;
      e.extra["image_mean"] = sum / static_cast<double>(f.image.size());
      e.extra["image_width"] = f.image_width;
      e.extra["image_last_blue"] = f.at(f.image_width - 1, f.image_height - 1, 2);
    }
    return e;
  }

 private:
  olp::Pose pose_;
};

int main() {
  DeadReckoning loc;
  return olp::serve(loc);
}
