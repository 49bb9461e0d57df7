#pragma once
// A recording's bounds, computed while it is made (docs/results.md "Cost."): every replay of its frames
// scores them with the same estimate-free bound part, so the part is kept in the bound cache
// (harness/bound_cache.hpp) for a localizer given its start pose and for one not, beside the rendering
// it is a small part of, and even the first replay reads it. Fed through RecordOptions::on_frame by
// `omniloc record` and the world cache's draws; the recorder itself knows nothing of scoring.
// Without a cache (OMNILOC_CACHE=off) it keeps nothing and holds nothing.
#include <vector>

#include "harness/bound_cache.hpp"
#include "harness/frame_data.hpp"
#include "harness/run_record.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

class BoundPreparer {
 public:
  /// `sc` (the recorded scenario) must outlive the preparer.
  explicit BoundPreparer(const Scenario& sc);
  /// One recorded frame: what the bound reads of each robot's.
  void add(const FrameData& f);
  /// Computes and keeps each robot's bound part, both start-pose cases, unless already kept.
  void finish();

 private:
  const Scenario& sc_;
  BoundCache cache_;  ///< no folder (OMNILOC_CACHE=off): nothing is held or kept
  std::vector<RobotRecord> robots_;
};

}  // namespace omniloc::harness
