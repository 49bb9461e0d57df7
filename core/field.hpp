#pragma once
// The field model: every painted marking as a segment, arc or spot (their centre lines, with the
// painted width), goals and landmarks, all in the world frame (metres, origin at the centre spot,
// x towards the opponent goal). Distances are exact to the marking centre lines.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/angles.hpp"
#include "core/json_reader.hpp"

namespace omniloc {

struct SegmentMarking {
  Eigen::Vector2d a, b;  ///< end points of the centre line, metres
};

struct ArcMarking {
  Eigen::Vector2d centre;
  double radius = 0.0;       ///< metres
  double start = 0.0;        ///< radians, arc runs anticlockwise from start ...
  double sweep = kTwoPi;     ///< ... over sweep radians (2 pi = full circle)
};

struct SpotMarking {
  Eigen::Vector2d centre;
  double radius = 0.0;  ///< painted disc radius, metres
};

struct Goal {
  double goal_line_x = 0.0;  ///< x of the goal line centre, metres (sign gives the side)
  double width = 2.0;        ///< inner distance between the posts, metres
  double depth = 0.6;        ///< how far the net reaches behind the goal line, metres
  double height = 1.0;       ///< crossbar height, metres
  double post_width = 0.125; ///< square posts, metres
  std::string colour = "white";  ///< "white" (nets since 2008), "yellow" or "blue" (legacy field)
  /// Outward direction (+1 for the goal at +x).
  int side() const { return goal_line_x >= 0 ? 1 : -1; }
  Eigen::Vector2d left_post() const;   ///< post centre on the goal's left as seen from the field
  Eigen::Vector2d right_post() const;
};

struct Landmark {
  std::string id;
  std::string colour;      ///< e.g. "red", "blue", "yellow"
  std::string shape = "cube";  ///< "cube" or "post"
  Eigen::Vector2d position;    ///< world frame, metres
  double size = 0.3;           ///< edge length or diameter, metres
  double height = 0.3;         ///< metres
};

class Field {
 public:
  std::string name;
  double length = 18.0;      ///< between the goal-line centres, metres
  double width = 12.0;       ///< between the touch-line centres, metres
  double line_width = 0.125; ///< painted width of every line, metres
  double margin = 1.0;       ///< floor between the outer line centres and the walls, metres
  double wall_height = 0.5;  ///< metres
  std::vector<SegmentMarking> segments;
  std::vector<ArcMarking> arcs;
  std::vector<SpotMarking> spots;
  std::vector<Goal> goals;
  std::vector<Landmark> landmarks;

  /// Exact distance from a world point to the nearest marking centre line (spots: to their rim, 0 inside).
  double distance_to_marking(const Eigen::Vector2d& p) const;
  /// True where white paint is: within line_width / 2 of a line or inside a spot.
  bool on_marking(const Eigen::Vector2d& p) const { return distance_to_marking(p) <= 0.5 * line_width; }
  /// Half extents of the floor inside the walls (metres).
  double half_floor_x() const { return 0.5 * length + margin; }
  double half_floor_y() const { return 0.5 * width + margin; }
  bool inside_floor(const Eigen::Vector2d& p, double clearance = 0.0) const;
  /// True when the field has coloured goals (legacy field) or coloured landmarks: what blob
  /// detection and landmark localizers work with.
  bool has_coloured_objects() const;
  /// Stable fingerprint of the geometry: caches (distance maps, colour tables) are tagged with it.
  std::string fingerprint() const;

  /// The painted markings as explicit geometry, world frame, metres: {"name", "length", "width",
  /// "margin", "segments": [[ax, ay, bx, by]...], "arcs": [[cx, cy, r, start, sweep]...], "spots":
  /// [[cx, cy, r]...], "goals": [[goal_line_x, width, depth]...]}. Written beside each run
  /// (field.json) so plots can draw the field under trajectories without knowing the presets.
  Json markings_json() const;
  /// Builds a field from JSON (see docs/scenario.md, "field"). Errors name the JSON path.
  static Field from_json(const Json& j, const std::string& path);
  /// Loads a named preset from data/fields/<name>.json.
  static Field preset(const std::string& name, const std::string& path = "/field");
  static std::vector<std::string> preset_names();
};

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b);
double distance_to_arc(const Eigen::Vector2d& p, const ArcMarking& arc);

/// Directory holding data files (field presets, noise profiles...): $OMNILOC_DATA_DIR, else
/// share_dir()/data (core/install_paths.hpp: an installed package's share/omniloc or the source tree).
std::string data_dir();

}  // namespace omniloc
