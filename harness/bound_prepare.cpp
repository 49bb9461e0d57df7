#include "harness/bound_prepare.hpp"

namespace omniloc::harness {

BoundPreparer::BoundPreparer(const Scenario& sc) : sc_(sc), cache_(bound_cache_from_env()) {}

void BoundPreparer::add(const FrameData& f) {
  if (cache_.options().dir.empty()) return;
  robots_.resize(f.robots.size());
  for (std::size_t i = 0; i < f.robots.size(); ++i) {
    robots_[i].id = f.robots[i].id;
    robots_[i].frames.push_back(bound_frame(f.robots[i]));
  }
}

void BoundPreparer::finish() {
  for (const RobotRecord& rec : robots_)
    for (const bool given : {true, false}) {
      const BoundSetup setup = bound_setup(sc_, rec.id, given);
      const std::string key = bound_key(rec, setup);
      if (!cache_.find(key, rec.frames.size())) cache_.store(key, bound_part(rec, setup));
    }
  robots_.clear();
}

}  // namespace omniloc::harness
