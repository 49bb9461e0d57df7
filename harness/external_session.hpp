#pragma once
// What an external localizer's client is told about its run in hello (docs/protocol.md, section 5):
// the robot, the field as every team has it, and the camera's image size and calibration, taken
// from the same Perception the built-in vision uses.
#include <cstdint>
#include <string>

#include "external/external_localizer.hpp"
#include "harness/perception.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

/// hello.field: field.json's markings plus goal colours and landmarks.
Json field_for_client(const Field& field);
/// hello.camera: image size, layout, mirror centre and the calibration tables (empty object when
/// `map` is null: nothing is rendered).
Json camera_for_client(const CalibrationMap* map);

/// The session of robot `robot`'s client: `camera` is hello.camera (camera_for_client), to which
/// the scenario's declared latency is added as `latency_s`; `blobs` whether frames can carry blobs.
external::Session make_session(const Scenario& sc, int robot, const Json& camera, bool blobs, std::uint64_t localizer_seed,
                               const std::string& log_dir);

}  // namespace omniloc::harness
