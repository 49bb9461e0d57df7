#pragma once
// Off-line vision set-up, as a team does it before a match: the model-free mirror calibration
// (`omniloc calibrate`) and the colour table (`omniloc colour-calibrate`), both produced by rendering
// with the simulated camera and processing the images with the robot-side code. Results are cached in
// the cache root's vision/ folder (core/cache_root.hpp) under a hash of the camera configuration (and
// field), so runs share them.
#include <cstdint>
#include <string>

#include "core/field.hpp"
#include "localization/vision/calibration_map.hpp"
#include "localization/vision/colour_table.hpp"
#include "sim/render/camera_config.hpp"

namespace omniloc::harness {

/// Where the calibration takes the mirror axis from.
enum class CentreSource {
  kRim,          ///< estimated from the mirror rim in the calibration images (the default)
  kImageCentre,  ///< assumed at the image centre (calibration before commit 0d6c7b9: a decentred mirror becomes error)
};

/// Renders the calibration patch in 36 directions while the robot turns on an empty floor, finds
/// the mirror axis and the edges and builds the map. `report`: optional, gets the map's error
/// against the true mirror by distance and the estimated and true centres (a JSON object) for the docs.
CalibrationResult calibrate_camera(const sim::CameraConfig& cfg, std::uint64_t seed, Json* report = nullptr,
                                   CentreSource centre = CentreSource::kRim);

/// Renders labelled frames of the field under normal light (observer at seeded random poses with
/// robots and the ball around it) and learns the table.
ColourTable colour_calibrate(const sim::CameraConfig& cfg, const Field& field, std::uint64_t seed, int frames = 12);

/// Tag identifying a camera configuration (what a calibration map was made for).
std::string camera_tag(const sim::CameraConfig& cfg);

/// The cache file of `cfg`'s calibration map (<cache root>/vision/calibration_v2_<tag>.json); "" when
/// caching is off.
std::string calibration_cache_file(const sim::CameraConfig& cfg);
/// The cache file of the colour table for `cfg` on `field` (<cache root>/vision/colour_v2_<tag>_<field>.lut);
/// "" when caching is off.
std::string colour_table_cache_file(const sim::CameraConfig& cfg, const Field& field);
/// The map for `cfg`: from `path` when given ("auto" = cached, calibrating when missing).
/// A perfect calibration: the simulator's true mirror profile and centre in the map's format (no
/// tilt). A measurement-model baseline for the error budget ("calibration": "exact"), never a default.
CalibrationMap exact_calibration(const sim::CameraConfig& cfg);
/// "auto": the model-free calibration (cached in the cache root), "exact": exact_calibration, else a map file.
CalibrationMap calibration_for(const sim::CameraConfig& cfg, const std::string& path, std::uint64_t seed);
/// The colour table for `cfg` and `field`: from `path` when given ("auto" = cached or learned).
ColourTable colour_table_for(const sim::CameraConfig& cfg, const Field& field, const std::string& path, std::uint64_t seed);

}  // namespace omniloc::harness
