#pragma once
// Coloured blobs on the panorama (papers 004 and 003: goals and colour cubes). Pixels of the
// annulus outside the robot's own body (and inside the image circle) are classified with the
// colour table; each wanted colour's 8-connected components are the regions; components under
// min_area_px are dropped (noise, mixed pixels along colour borders). Only a grid is classified
// up front and regions are grown from it (see detect(): the same regions as classifying every
// pixel, detect_full(), in a fifth of the time). Per region:
//  - bearing: the middle of its angular extent around the mirror axis. A central catadioptric
//    camera on a vertical axis images vertical edges as radial lines, so the extent is that of the
//    object's footprint seen from the robot, whatever its height;
//  - left / right edge bearings (anticlockwise / clockwise ends of the extent);
//  - distance: the region pixel nearest the image centre is the object's nearest ground contact
//    (points higher up look out at a higher elevation, farther from the centre); its floor distance
//    comes from the calibration map (none beyond the calibrated radius or when the contact hides
//    behind the robot's body);
//  - occlusion: an edge whose angular neighbourhood (edge_band_px beyond it, along the region's
//    radii) is mostly obstacle black (a robot, a blackened sector) or outside the image may be a cut,
//    not the object's edge.
// For goal colours (edge_colours) the two edges are also given as separate observations
// (Blob::Kind::kLeftEdge / kRightEdge), their distance taken near that edge. Units and frames as in
// localization/localizer.hpp (Blob).
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/messages.hpp"
#include "localization/localizer.hpp"
#include "localization/vision/calibration_map.hpp"
#include "localization/vision/colour_table.hpp"

namespace omniloc {

struct BlobParams {
  /// Colour classes searched for ("yellow", "blue", "red" in JSON).
  std::vector<ColourClass> colours = {kYellow, kBlue, kRed};
  /// Colours whose regions also give left / right edge observations (goal colours). Empty by
  /// default; the harness fills in the field's coloured goals unless the scenario lists them.
  std::vector<ColourClass> edge_colours;
  int min_area_px = 25;          ///< pixels: smaller regions are ignored
  /// Pixels searched: from the calibration map's inner radius (the robot's body inside) out to this
  /// radius; 0 = the image's inscribed circle. Beyond the calibrated radius bearings are still
  /// measured (far goals sit near the mirror rim) but distances are not.
  double outer_radius_px = 0.0;
  double dark_mean = 15.0;       ///< mean grey of the annulus below this: camera covered, no blobs
  /// The angular extent runs between the outermost region pixels' centres, widened by this many
  /// pixels on each side. 0 by measurement: mixed pixels along an edge mostly classify as the
  /// object's colour, so the outermost centres already lie on the edge (0.5 gave 0.1-0.13 degrees
  /// too wide an extent on the rendered goals and cubes, ~0.5 px).
  double edge_extend_px = 0.0;
  int edge_band_px = 3;          ///< pixels beyond an edge checked for an occluder
  double occluded_fraction = 0.3;  ///< fraction of those pixels that must be black (or off-image)
  double edge_contact_deg = 1.5;   ///< an edge's distance: nearest region pixel within this angle of it
  static BlobParams from_json(JsonReader& r);
  /// The numeric JSON keys (scenario /vision/blobs); "colours" and "edge_colours" are lists of names.
  static const ParamList<BlobParams>& params();
};

class BlobDetector {
 public:
  /// Precomputes per-pixel bearing and radius tables for the map's image size.
  BlobDetector(const BlobParams& p, const CalibrationMap& map, const ColourTable& table);
  /// Regions (and edges for edge colours), sorted by colour, then kind, then bearing. Empty when the
  /// image is dark (see dark_mean) or of another size than the calibration map.
  ///
  /// Only a grid of rows and columns is classified up front (every grid_rows()-th row, every
  /// grid_cols()-th column); each wanted-colour grid pixel seeds a flood fill that classifies pixels
  /// as it reaches them. A component that misses the grid lies between two grid rows and two grid
  /// columns (8-connected steps cannot jump a line), so it has at most (grid_rows() - 1) *
  /// (grid_cols() - 1) pixels, which is below min_area_px: every region detect_full() reports is
  /// found, with the same pixels, hence the same blobs.
  std::vector<Blob> detect(const Image& img) const;
  /// The same blobs with every annulus pixel classified and OpenCV's connected components per colour
  /// (the straightforward form; for tests and measurements, several times slower).
  std::vector<Blob> detect_full(const Image& img) const;
  int grid_rows() const { return grid_rows_; }
  int grid_cols() const { return grid_cols_; }
  /// Mean grey (0-255) of the annulus of `img`, sampled every 4th pixel.
  double mean_grey(const Image& img) const;
  const BlobParams& params() const { return p_; }

 private:
  BlobParams p_;
  const CalibrationMap& map_;
  const ColourTable& table_;
  int w_ = 0, h_ = 0;
  std::vector<float> bearing_;   // per pixel, robot-frame bearing of the pixel centre, radians
  std::vector<float> radius_;    // per pixel, distance of the pixel centre from the mirror axis, px
  std::vector<std::uint8_t> inside_;  // 1 in the searched annulus
  // The annulus as runs [u0, u1) per row: row v's runs are runs_[row_runs_[v] .. row_runs_[v + 1]).
  std::vector<std::pair<int, int>> runs_;
  std::vector<int> row_runs_;
  int grid_rows_ = 1, grid_cols_ = 1;  // see detect()

  struct Component;
  // Appends the blobs of one component; `cls` holds classes, kUnclassified (classified here when
  // read) or visited marks (see blobs.cpp).
  void measure(const Image& img, std::uint8_t* cls, const Component& comp, std::vector<Blob>& out) const;
  /// The image has the calibrated size and is not dark (see dark_mean): worth searching.
  bool usable(const Image& img) const;
  /// Indexed by colour class: true for the classes searched for (p_.colours).
  std::array<bool, 256> wanted_classes() const;
};

}  // namespace omniloc
