// `omniloc calibrate` (the mirror map) and `omniloc colour-calibrate` (the colour table) of a scenario's camera.
#include "apps/commands.hpp"

#include <cstdio>
#include <iostream>

#include "apps/command_support.hpp"
#include "harness/scenario.hpp"
#include "harness/vision_setup.hpp"
#include "sim/render/camera_config.hpp"

namespace omniloc::app {

const cli::Command kCalibrate{"calibrate", "FILE", 1, 1,
                              "Model-free mirror calibration with the scenario's camera; prints the map's error against the true mirror.",
                              {{"-o", "MAP.json", "output map (default: the cache's vision/calibration_v2_<camera>.json, which runs use); an existing file only with --overwrite"},
                               {"--overwrite", "", "replace an existing -o file"},
                               {"--seed", "N", "seed (default 1)"},
                               {"--image-centre", "", "assume the mirror axis at the image centre instead of estimating it from the rim (saved only with -o)"}}};
const cli::Command kColourCalibrate{"colour-calibrate", "FILE", 1, 1, "Learn the colour look-up table from labelled renders of the scenario's field.",
                                    {{"-o", "TABLE.lut", "output table (default: the cache's vision/colour_v2_<camera>_<field>.lut, which runs use); an existing file only with --overwrite"},
                                     {"--overwrite", "", "replace an existing -o file"},
                                     {"--seed", "N", "seed (default 1)"}}};

int cmd_calibrate(const cli::Args& a) {
  check_output_target(a, false);  // an explicit -o; the default is the shared cache, which calibrating refreshes
  const std::uint64_t seed = a.unsigned_integer("--seed", 1, kMaxSeed);
  const auto s = harness::load_scenario(a.positional[0]);
  const auto cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  Json report;
  const bool image_centre = a.has("--image-centre");
  auto r = harness::calibrate_camera(cfg, seed, &report, image_centre ? harness::CentreSource::kImageCentre : harness::CentreSource::kRim);
  // An image-centre map is a comparison, not what runs should pick up from the cache.
  // Runs compute the seed-1 map when the cache has none; another seed's map goes only where -o says.
  if (!a.has("-o") && seed != 1 && !image_centre) throw UsageError("calibrate --seed " + std::to_string(seed) + " needs -o MAP.json: the cache holds the seed-1 map every run computes");
  const std::string out = a.value("-o", image_centre ? std::string() : harness::calibration_cache_file(cfg));
  if (!out.empty()) r.map.save(out);
  std::printf("directions used %d, rejected %d\n", r.directions_used, r.directions_rejected);
  const auto& c = report["centre_px"];
  const auto& t = report["true_centre_px"];
  if (image_centre)
    std::printf("mirror centre: image centre (%.2f, %.2f) assumed; true (%.2f, %.2f), off by %.2f px\n", c[0].get<double>(), c[1].get<double>(),
                t[0].get<double>(), t[1].get<double>(), report["centre_error_px"].get<double>());
  else
    std::printf("mirror centre: estimated (%.2f, %.2f) from the rim (radius %.2f px, rms %.3f px, %d points, %d rejected);\n"
                "               true (%.2f, %.2f), radius %.2f px: off by %.3f px\n",
                c[0].get<double>(), c[1].get<double>(), report["rim_radius_px"].get<double>(), report["rim_rms_px"].get<double>(),
                report["rim_points"].get<int>(), report["rim_rejected"].get<int>(), t[0].get<double>(), t[1].get<double>(),
                report["true_rim_radius_px"].get<double>(), report["centre_error_px"].get<double>());
  std::printf("%10s %12s %12s %12s\n", "distance m", "mean err cm", "p95 err cm", "max err cm");
  for (const auto& row : report["error_by_distance"])
    std::printf("%10.1f %12.2f %12.2f %12.2f\n", row["distance_m"].get<double>(), 100 * row["mean_error_m"].get<double>(),
                100 * row["p95_error_m"].get<double>(), 100 * row["max_error_m"].get<double>());
  if (!out.empty()) std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_colour_calibrate(const cli::Args& a) {
  check_output_target(a, false);  // an explicit -o; the default is the shared cache
  const std::uint64_t seed = a.unsigned_integer("--seed", 1, kMaxSeed);
  const auto s = harness::load_scenario(a.positional[0]);
  const auto cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  const ColourTable t = harness::colour_calibrate(cfg, s.field, seed);
  if (!a.has("-o") && seed != 1) throw UsageError("colour-calibrate --seed " + std::to_string(seed) + " needs -o TABLE.lut: the cache holds the seed-1 table every run computes");
  const std::string out = a.value("-o", harness::colour_table_cache_file(cfg, s.field));
  if (out.empty()) throw UsageError("colour-calibrate needs -o TABLE.lut when the cache is off");
  t.save(out);
  std::cout << "wrote " << out << "\n";
  return 0;
}

}  // namespace omniloc::app
