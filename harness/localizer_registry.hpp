#pragma once
// Localizers by name. Adding a localizer: one new file pair in localization/ and one entry in
// localizer_registry.cpp.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "external/external_localizer.hpp"
#include "harness/localizer_spec.hpp"
#include "localization/localizer.hpp"

namespace omniloc::harness {

/// What a localizer may know when it is built: the field (the map every team has), the camera's
/// declared latency (what a team measures once and configures) and a seed for its own random
/// stream. Never the simulator.
struct LocalizerContext {
  const Field* field = nullptr;
  std::uint64_t seed = 0;
  /// s: how much older the image is than the odometry it is paired with, as the scenario's camera
  /// declares it (its noise profile's `latency_ms`); 0 when nothing declares it (a log not made by
  /// omniloc). Never measured from the run.
  double camera_latency = 0.0;
  /// m: the mirror viewpoint's height above the floor as the scenario's camera declares it (its
  /// `mount_height`); 0 when not declared.
  double camera_mount_height = 0.0;
  /// rad: the camera's per-frame tilt (roll and pitch, each) as the scenario's camera declares it
  /// (its `vibration_deg`); 0 when none is declared.
  double camera_vibration = 0.0;
  std::string cache_dir;  ///< where distance maps etc. may be cached
  /// What an external localizer's client is told in hello (robot, field, camera, log folder); null
  /// outside a run (validation, experiments), where an external localizer cannot be built.
  const external::Session* session = nullptr;
};

struct LocalizerInfo {
  std::string type;
  std::string description;
  bool needs_start_pose = false;  ///< tracking-only localizers get the true start pose (papers' set-up)
  bool needs_vision = true;       ///< false: no images need to be rendered
  /// Reads parameters strictly (params reader at the localizer's JSON object; "type" already read)
  /// and builds the localizer.
  std::function<std::unique_ptr<Localizer>(JsonReader& params, const LocalizerContext& ctx)> make;
  /// JSON Schema properties of its parameters (from the parameter structs' field lists).
  std::function<Json()> schema;
  /// Checks the parameters without building (null: validation builds it with make): the same reads
  /// and the same errors as make's, without the tables a localizer builds (a distance map, an
  /// association grid: 10-80 ms a localizer, which `omniloc validate` paid for every file of a sweep).
  /// The external localizer checks its program here; building would start it.
  std::function<void(JsonReader& params, const LocalizerContext& ctx)> check = nullptr;
};

const std::vector<LocalizerInfo>& localizers();
/// Throws ConfigError naming `path` when the type is unknown.
const LocalizerInfo& localizer_info(const std::string& type, const std::string& path);

/// The registry's entry for the spec's type; LocalizerError naming its path/type when there is none.
const LocalizerInfo& localizer_info(const LocalizerSpec& l);

/// Reads the spec's {"type": ..., params...} strictly and builds the localizer. Throws LocalizerError.
std::unique_ptr<Localizer> make_localizer(const LocalizerSpec& l, const LocalizerContext& ctx, Json* effective = nullptr);
/// The same for a localizer object at `path` of an experiment's description.
std::unique_ptr<Localizer> make_localizer(const Json& j, const std::string& path, const LocalizerContext& ctx,
                                          Json* effective = nullptr);

/// Reads the spec strictly and checks it as far as possible without a run: built-in localizers are
/// built (and dropped), an external one's program is checked, not started. Throws LocalizerError.
void check_localizer(const LocalizerSpec& l, const LocalizerContext& ctx);

}  // namespace omniloc::harness
