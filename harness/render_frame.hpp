#pragma once
// `omniloc render`: the frame one robot's camera took at time t of a run, and the world of a
// scenario at a time.
#include <cstdint>
#include <string>

#include "core/messages.hpp"
#include "harness/scenario.hpp"
#include "sim/world_state.hpp"

namespace omniloc::harness {

/// The world of the scenario at time t (scripts, events, lighting; no camera, so no robot paused by
/// exposure control): the Simulation the run loop uses, advanced to t.
sim::WorldState world_at(const Scenario& s, double t, std::uint64_t seed);

/// The frame robot `robot_id` took at the last camera frame at or before t, as `omniloc run --frames`
/// saves it: the run's simulation and perception are replayed up to that frame (camera noise, latency,
/// exposure control and the pauses it asks for included). A robot that is not localized was never
/// rendered by the run: it gets the camera's initial settings and a fresh noise stream.
/// `labels`: the class image instead of colours. `points`: the line points the vision front end
/// finds, drawn in red. Writes a PNG (or JPEG by extension), atomically.
void render_to_png(const Scenario& s, double t, int robot_id, std::uint64_t seed, bool labels, const std::string& png_path,
                   bool points = false);

/// Writes an RGB image as PNG (atomically).
void write_png(const Image& img, const std::string& path);

}  // namespace omniloc::harness
