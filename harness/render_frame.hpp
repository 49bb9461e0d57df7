#pragma once
// `omniloc render`: the world of a scenario at time t, as one robot's camera sees it.
#include <cstdint>
#include <string>

#include "core/messages.hpp"
#include "harness/scenario.hpp"
#include "sim/world_state.hpp"

namespace omniloc::harness {

/// Simulates the scenario's motion (scripts, teleports, lighting) up to time t, without sensors
/// or localization, and returns the world state.
sim::WorldState world_at(const Scenario& s, double t, std::uint64_t seed);

/// Renders robot `robot_id` at time t (labels: the class image instead of colours). Writes a PNG.
/// `points`: overlay the line points the vision front end finds (red) on the colour image.
void render_to_png(const Scenario& s, double t, int robot_id, std::uint64_t seed, bool labels, const std::string& png_path,
                   bool points = false);

/// Writes an RGB image as PNG (atomically).
void write_png(const Image& img, const std::string& path);

}  // namespace omniloc::harness
