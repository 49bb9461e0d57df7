#pragma once
// The floor as the camera draws it: an image-fixed polar mesh (rings placed where the floor distance
// stops being linear in the image radius, as few sectors per ring as the floor's curvature allows)
// that carries, each frame, the lamps' light at the floor points its rays hit and which walls hide
// them; fragment shaders find each pixel's own floor point through the mirror (its elevation from a
// table of the mirror's law, the frame's tilt and pose) and turn a distance field of the field's
// markings into anti-aliased lines there; cells hidden behind the hall's walls left out. Also the
// sun beams on the carpet, drawn again over the mesh with the same shader.
// Kept apart from the standing scene because it is projected the other way round: from image to
// floor, not from world to image.
//
// Units: metres and radians in the world; pixels in the image. Frames: world (the distance field
// spans the floor inside the walls, x in [-hx, hx], y in [-hy, hy]); camera (each mesh vertex's unit
// ray); render space (the image times the supersampling factor, x right, y down).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/render/frame_projection.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/render/mirror.hpp"
#include "sim/world_state.hpp"

namespace omniloc::sim {

class FloorMesh {
 public:
  /// Uploads the distance field and compiles the floor shaders in `ctx` (current, framebuffer bound).
  /// Throws RuntimeFailure when the GL back-end fails.
  FloorMesh(GlContext& ctx, const Field& field, const CameraConfig& cfg, const MirrorProfile& mirror, int ss);
  ~FloorMesh();
  FloorMesh(const FloorMesh&) = delete;
  FloorMesh& operator=(const FloorMesh&) = delete;

  /// Clear colour: what is seen above the walls (the hall's far floor under the light at the robot).
  Eigen::Vector3f far_floor(const WorldState& world, const Pose2& pose, bool labels) const;
  /// The mesh, after everything standing: depth-tested, never written. `labels`: class ids.
  void draw(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels);
  /// The floor under each floor sun beam again, under the beam's light.
  void draw_sun_beams(const GlApi& gl, const FrameProjection& f, const WorldState& world);

 private:
  void upload_distance_field(const Field& field);
  void compile_programs(double line_half_width);
  void build_mesh(const CameraConfig& cfg, const MirrorProfile& mirror, int ss);
  /// The mirror's elevation per image radius as a texture, and the shaders' constant uniforms.
  void upload_mirror(const MirrorProfile& mirror, int ss);
  /// The frame's pose, tilt and mount height for `prog`'s per-pixel floor point.
  void set_frame_uniforms(const GlApi& gl, unsigned prog, const FrameProjection& f) const;
  /// Per mesh vertex: this frame's floor point and which walls hide it (hidden_).
  void place_vertices(const FrameProjection& f, const WorldState& world, bool labels);
  GlContext& ctx_;
  double hx_ = 0, hy_ = 0;   // floor half extents covered by the distance field, metres
  double wall_height_ = 0;   // metres
  unsigned tex_distance_ = 0;
  unsigned tex_elevation_ = 0;  // texture unit 1: elevation (rad) per image radius
  unsigned prog_floor_ = 0, prog_floor_inside_ = 0, prog_floor_labels_ = 0;
  std::vector<float> mesh_xy_;              // render-space positions
  std::vector<Eigen::Vector3d> mesh_dir_;   // camera-frame unit ray of each vertex
  std::vector<unsigned> mesh_idx_;
  // Per-frame scratch.
  std::vector<float> pos_, col_, tex_;
  std::vector<std::uint8_t> hidden_;  // per vertex: bits 0-3 behind a wall, bit 4 off the floor inside the walls
  std::vector<unsigned> idx_, idx_inside_;  // triangles drawn this frame (idx_inside_: all corners inside the walls)
};

}  // namespace omniloc::sim
