#pragma once
// Everything the camera sees that is not the floor mesh: the hall's walls, goals (posts, bar, nets)
// and landmarks, tessellated once at start-up with shared vertices so that each is projected once
// per frame; the other robots and the ball, tessellated per frame with the faces turned away from
// the camera left out; the sun on the walls, the flat patches on the carpet and the robot's own body
// in the image centre. Every vertex goes through the mirror (FrameProjection) and GL only
// rasterises, with depth testing; the floor mesh is the other half (floor_mesh.hpp).
//
// Units: metres and radians. Frames: triangles are kept in the world frame (x towards the opponent
// goal, y left, z up); FrameProjection takes them to render space (the image times the
// supersampling factor, pixels, x right, y down).
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "sim/render/frame_projection.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/world_state.hpp"

namespace omniloc::sim {

class SceneMesh {
 public:
  struct Tri {
    std::array<Eigen::Vector3d, 3> p;  // world frame, metres
    Eigen::Vector3f albedo;
    std::uint8_t label;
    Eigen::Vector3d facing = Eigen::Vector3d::Zero();  // outward normal of a closed solid's face; zero: seen from both sides
  };
  // Triangles with their corners as shared vertices, so that each vertex is projected through the
  // mirror once per frame instead of once per triangle using it (a grid vertex is a corner of up to six).
  struct SharedTris {
    std::vector<Tri> tris;
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<unsigned, 3>> corners;  // per triangle, indices into vertices
  };

  /// Tessellates the static scene: walls, goals, landmarks.
  explicit SceneMesh(const Field& field);

  /// Walls, the sun on them, other robots, the ball, goals and landmarks (depth written). `labels`:
  /// flat class colours, no lighting.
  void draw_standing(const GlApi& gl, const FrameProjection& f, const WorldState& world, const RobotState& me, bool labels);
  /// Flat patches on the carpet: over the floor, under everything standing.
  void draw_floor_patches(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels);
  /// The robot's own body, a disc in the image centre (its brightness follows the light on the robot).
  void draw_body(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels);

 private:
  // kSolid: depth-tested and written; kOverWall: painted without a test; kOnFloor: at the far plane,
  // tested, not written (under everything standing).
  enum class Layer { kSolid, kOverWall, kOnFloor };
  /// One draw of `shared` (optional, first) and `list`. fixed_light >= 0: every triangle under that
  /// illumination instead of the floor light at its middle.
  void emit(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels, const std::vector<Tri>& list, Layer layer,
            double fixed_light = -1.0, const SharedTris* shared = nullptr);

  double hx_ = 0, hy_ = 0, wall_height_ = 0;  // the hall's inner walls, metres
  SharedTris walls_;
  SharedTris statics_;  // goals, landmarks
  // Per-draw scratch.
  std::vector<float> pos_, col_;
  std::vector<float> shared_xyz_;  // this frame's projections of a SharedTris' vertices
};

}  // namespace omniloc::sim
