// The standing scene: tessellation of walls, goals, landmarks, robots and the ball, and its draws
// (see scene_mesh.hpp). Units: metres, radians; triangles in the world frame, projected to render
// space per vertex.
#include "sim/render/scene_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "core/angles.hpp"
#include "sim/render/label_class.hpp"
#include "sim/render/photometry.hpp"

namespace omniloc::sim {

namespace {

using Tri = SceneMesh::Tri;
using SharedTris = SceneMesh::SharedTris;

// Linear albedos (reflectances) of what stands on the floor.
const Eigen::Vector3f kWall(0.14f, 0.14f, 0.20f);
const Eigen::Vector3f kRobot(0.05f, 0.05f, 0.05f);
const Eigen::Vector3f kBall(0.85f, 0.30f, 0.05f);
const Eigen::Vector3f kPost(0.85f, 0.85f, 0.85f);
const Eigen::Vector3f kNet(0.50f, 0.52f, 0.50f);
const Eigen::Vector3f kBody(0.35f, 0.35f, 0.35f);

Eigen::Vector3f colour_of(const std::string& c) {
  if (c == "yellow") return {0.85f, 0.78f, 0.08f};
  if (c == "blue") return {0.08f, 0.18f, 0.75f};
  if (c == "red") return {0.80f, 0.08f, 0.08f};
  if (c == "green") return {0.10f, 0.60f, 0.15f};
  if (c == "magenta") return {0.75f, 0.10f, 0.65f};
  if (c == "cyan") return {0.10f, 0.65f, 0.75f};
  return kPost;
}
std::uint8_t label_of(const std::string& c) {
  if (c == "yellow") return kLabelYellow;
  if (c == "blue") return kLabelBlue;
  if (c == "red") return kLabelRed;
  return kLabelGoal;
}

// Tessellated primitives in world coordinates.
void add_quad(std::vector<Tri>& out, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
              const Eigen::Vector3d& d, const Eigen::Vector3f& alb, std::uint8_t lab, double max_edge,
              const Eigen::Vector3d& facing = Eigen::Vector3d::Zero()) {
  // Subdivide a planar quad a-b-c-d (in order) into a grid whose cells are at most max_edge.
  const int nu = std::max(1, static_cast<int>(std::ceil(std::max((b - a).norm(), (c - d).norm()) / max_edge)));
  const int nv = std::max(1, static_cast<int>(std::ceil(std::max((d - a).norm(), (c - b).norm()) / max_edge)));
  auto at = [&](int i, int j) {
    const double u = static_cast<double>(i) / nu, v = static_cast<double>(j) / nv;
    return Eigen::Vector3d((1 - v) * ((1 - u) * a + u * b) + v * ((1 - u) * d + u * c));
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      out.push_back({{at(i, j), at(i + 1, j), at(i + 1, j + 1)}, alb, lab, facing});
      out.push_back({{at(i, j), at(i + 1, j + 1), at(i, j + 1)}, alb, lab, facing});
    }
}

void add_box(std::vector<Tri>& out, const Eigen::Vector2d& c, double hx, double hy, double angle, double z0, double z1,
             const Eigen::Vector3f& alb, std::uint8_t lab, double max_edge) {
  const double ca = std::cos(angle), sa = std::sin(angle);
  auto corner = [&](double sx, double sy, double z) {
    return Eigen::Vector3d(c.x() + ca * sx * hx - sa * sy * hy, c.y() + sa * sx * hx + ca * sy * hy, z);
  };
  const double xs[4] = {-1, 1, 1, -1}, ys[4] = {-1, -1, 1, 1};
  for (int k = 0; k < 4; ++k) {
    const int n = (k + 1) % 4;
    const Eigen::Vector3d mid = 0.5 * (corner(xs[k], ys[k], z0) + corner(xs[n], ys[n], z0));
    add_quad(out, corner(xs[k], ys[k], z0), corner(xs[n], ys[n], z0), corner(xs[n], ys[n], z1), corner(xs[k], ys[k], z1), alb, lab, max_edge,
             Eigen::Vector3d(mid.x() - c.x(), mid.y() - c.y(), 0.0));
  }
  add_quad(out, corner(-1, -1, z1), corner(1, -1, z1), corner(1, 1, z1), corner(-1, 1, z1), alb, lab, max_edge, Eigen::Vector3d::UnitZ());
}

// `eye` (world, metres), when given: the faces turned away from it are left out (the depth test
// hides them anyway; llvmpipe's cost per triangle is not small).
void add_cylinder(std::vector<Tri>& out, const Eigen::Vector2d& c, double r, double z0, double z1, const Eigen::Vector3f& alb,
                  std::uint8_t lab, int sides, int rows, const Eigen::Vector3d* eye = nullptr) {
  for (int k = 0; k < sides; ++k) {
    const double a0 = kTwoPi * k / sides, a1 = kTwoPi * (k + 1) / sides;
    const Eigen::Vector2d p0 = c + r * Eigen::Vector2d(std::cos(a0), std::sin(a0));
    const Eigen::Vector2d p1 = c + r * Eigen::Vector2d(std::cos(a1), std::sin(a1));
    // A side facet is out of sight from behind its plane.
    if (eye && (0.5 * (p0 + p1) - c).dot(eye->head<2>() - p0) <= 0) continue;
    for (int j = 0; j < rows; ++j) {
      const double za = z0 + (z1 - z0) * j / rows, zb = z0 + (z1 - z0) * (j + 1) / rows;
      out.push_back({{Eigen::Vector3d(p0.x(), p0.y(), za), Eigen::Vector3d(p1.x(), p1.y(), za), Eigen::Vector3d(p1.x(), p1.y(), zb)}, alb, lab});
      out.push_back({{Eigen::Vector3d(p0.x(), p0.y(), za), Eigen::Vector3d(p1.x(), p1.y(), zb), Eigen::Vector3d(p0.x(), p0.y(), zb)}, alb, lab});
    }
    if (!eye || eye->z() > z1)  // the top is out of sight from below
      out.push_back({{Eigen::Vector3d(c.x(), c.y(), z1), Eigen::Vector3d(p0.x(), p0.y(), z1), Eigen::Vector3d(p1.x(), p1.y(), z1)}, alb, lab});
  }
}

void add_sphere(std::vector<Tri>& out, const Eigen::Vector3d& c, double r, const Eigen::Vector3f& alb, std::uint8_t lab,
                const Eigen::Vector3d& eye) {
  const int nl = 8, na = 14;
  auto pt = [&](int i, int j) {
    const double th = kPi * i / nl, ph = kTwoPi * j / na;
    return Eigen::Vector3d(c + r * Eigen::Vector3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
  };
  for (int i = 0; i < nl; ++i)
    for (int j = 0; j < na; ++j) {
      // A patch is out of sight when all its corners face away from the eye.
      bool seen = false;
      for (const auto& q : {pt(i, j), pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1)}) seen = seen || (q - c).dot(eye - q) > 0;
      if (!seen) continue;
      out.push_back({{pt(i, j), pt(i + 1, j), pt(i + 1, j + 1)}, alb, lab});
      out.push_back({{pt(i, j), pt(i + 1, j + 1), pt(i, j + 1)}, alb, lab});
    }
}

SharedTris share_vertices(std::vector<Tri> tris) {
  SharedTris out;
  std::map<std::array<double, 3>, unsigned> index;
  for (const Tri& t : tris) {
    std::array<unsigned, 3> c{};
    for (int k = 0; k < 3; ++k) {
      const auto [it, added] = index.try_emplace({t.p[k].x(), t.p[k].y(), t.p[k].z()}, static_cast<unsigned>(out.vertices.size()));
      if (added) out.vertices.push_back(t.p[k]);
      c[k] = it->second;
    }
    out.corners.push_back(c);
  }
  out.tris = std::move(tris);
  return out;
}

// The lit rectangle of a wall sun patch: a quad 1 cm in front of the inner face of the hall wall
// nearest to the patch centre (drawn over the wall like floor patches over the carpet, so its edges
// stay sharp whatever the wall's tessellation). Empty when the patch misses the wall.
bool wall_patch_quad(const SunPatch& sp, double hx, double hy, double wall_height, std::array<Eigen::Vector3d, 4>& q) {
  const double in = 0.01;
  const Eigen::Vector2d c = sp.centre;
  const double d[4] = {std::fabs(c.x() - hx), std::fabs(c.x() + hx), std::fabs(c.y() - hy), std::fabs(c.y() + hy)};
  const int k = static_cast<int>(std::min_element(d, d + 4) - d);
  const bool along_y = k < 2;  // walls at x = +-hx run along y
  const double extent = along_y ? hy : hx;
  const double a0 = std::max(-extent, (along_y ? c.y() : c.x()) - sp.half_size.x());
  const double a1 = std::min(extent, (along_y ? c.y() : c.x()) + sp.half_size.x());
  const double z0 = std::max(0.0, sp.z_min), z1 = std::min(wall_height, sp.z_max);
  if (a1 <= a0 || z1 <= z0) return false;
  const double face = k == 0 ? hx - in : k == 1 ? -hx + in : k == 2 ? hy - in : -hy + in;
  auto pt = [&](double a, double z) { return along_y ? Eigen::Vector3d(face, a, z) : Eigen::Vector3d(a, face, z); };
  q = {pt(a0, z0), pt(a1, z0), pt(a1, z1), pt(a0, z1)};
  return true;
}

// Posts, crossbar and net panels (coloured inside on the legacy field).
void add_goal(std::vector<Tri>& out, const Goal& g) {
  const bool coloured = g.colour != "white";
  const Eigen::Vector3f post = coloured ? colour_of(g.colour) : kPost;
  const std::uint8_t plab = coloured ? label_of(g.colour) : std::uint8_t{kLabelGoal};
  const double hp = 0.5 * g.post_width, s = g.side();
  for (const Eigen::Vector2d& pp : {g.left_post(), g.right_post()}) add_box(out, pp, hp, hp, 0, 0, g.height, post, plab, 0.15);
  const double yw = 0.5 * g.width + g.post_width;
  add_box(out, {g.goal_line_x, 0}, hp, yw, 0, g.height - g.post_width, g.height, post, plab, 0.15);
  const Eigen::Vector3f net = coloured ? colour_of(g.colour) : kNet;
  const std::uint8_t nlab = coloured ? label_of(g.colour) : std::uint8_t{kLabelGoal};
  const double x0 = g.goal_line_x + s * hp, x1 = g.goal_line_x + s * g.depth;
  add_quad(out, {x1, -yw, 0}, {x1, yw, 0}, {x1, yw, g.height}, {x1, -yw, g.height}, net, nlab, 0.2);
  add_quad(out, {x0, -yw, 0}, {x1, -yw, 0}, {x1, -yw, g.height}, {x0, -yw, g.height}, net, nlab, 0.2);
  add_quad(out, {x0, yw, 0}, {x1, yw, 0}, {x1, yw, g.height}, {x0, yw, g.height}, net, nlab, 0.2);
  add_quad(out, {x0, -yw, g.height}, {x1, -yw, g.height}, {x1, yw, g.height}, {x0, yw, g.height}, net, nlab, 0.2);
}

}  // namespace

SceneMesh::SceneMesh(const Field& field) : hx_(field.half_floor_x()), hy_(field.half_floor_y()), wall_height_(field.wall_height) {
  std::vector<Tri> wall_tris, static_tris;
  const double wall_t = 0.1, wh = field.wall_height;
  if (wh > 0) {
    // Only what can be seen from inside the hall: each wall's inner face and its top.
    const double ex = hx_ + 2 * wall_t;
    auto wall = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& out) {
      const Eigen::Vector2d a2 = a + 2 * wall_t * out, b2 = b + 2 * wall_t * out;
      add_quad(wall_tris, {a.x(), a.y(), 0}, {b.x(), b.y(), 0}, {b.x(), b.y(), wh}, {a.x(), a.y(), wh}, kWall, kLabelWall, 0.6);
      add_quad(wall_tris, {a.x(), a.y(), wh}, {b.x(), b.y(), wh}, {b2.x(), b2.y(), wh}, {a2.x(), a2.y(), wh}, kWall, kLabelWall, 0.6);
    };
    wall({-ex, hy_}, {ex, hy_}, {0, 1});
    wall({-ex, -hy_}, {ex, -hy_}, {0, -1});
    wall({hx_, -hy_}, {hx_, hy_}, {1, 0});
    wall({-hx_, -hy_}, {-hx_, hy_}, {-1, 0});
  }
  for (const auto& g : field.goals) add_goal(static_tris, g);
  for (const auto& l : field.landmarks) {
    if (l.shape == "post")
      add_cylinder(static_tris, l.position, 0.5 * l.size, 0, l.height, colour_of(l.colour), label_of(l.colour), 16, 6);
    else
      add_box(static_tris, l.position, 0.5 * l.size, 0.5 * l.size, 0, 0, l.height, colour_of(l.colour), label_of(l.colour), 0.1);
  }
  walls_ = share_vertices(std::move(wall_tris));
  statics_ = share_vertices(std::move(static_tris));
}

void SceneMesh::emit(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels, const std::vector<Tri>& list,
                     Layer layer, double fixed_light, const SharedTris* shared) {
  pos_.clear();
  col_.clear();
  auto append = [&](const Tri& t, const std::array<const float*, 3>& corners) {
    const Eigen::Vector2d mid = (t.p[0].head<2>() + t.p[1].head<2>() + t.p[2].head<2>()) / 3.0;
    const float illum = static_cast<float>((fixed_light >= 0 ? fixed_light : world.lighting.at(mid)) / kRadianceScale);
    for (const float* xyz : corners) {
      pos_.insert(pos_.end(), {xyz[0], xyz[1], layer == Layer::kOnFloor ? -999.0f : xyz[2]});
      if (labels) {
        const float l = t.label / 255.0f;
        col_.insert(col_.end(), {l, l, l, 1.0f});
      } else {
        col_.insert(col_.end(), {std::min(1.0f, t.albedo[0] * illum), std::min(1.0f, t.albedo[1] * illum),
                                 std::min(1.0f, t.albedo[2] * illum), 1.0f});
      }
    }
  };
  // A face of a solid turned away from the eye is hidden behind the solid.
  auto turned_away = [&](const Tri& t) { return t.facing.dot(f.eye - t.p[0]) < 0; };
  if (shared) {
    shared_xyz_.resize(3 * shared->vertices.size());
    for (std::size_t i = 0; i < shared->vertices.size(); ++i) f(shared->vertices[i], &shared_xyz_[3 * i]);
    for (std::size_t k = 0; k < shared->tris.size(); ++k) {
      if (turned_away(shared->tris[k])) continue;
      const auto& c = shared->corners[k];
      append(shared->tris[k], {&shared_xyz_[3 * c[0]], &shared_xyz_[3 * c[1]], &shared_xyz_[3 * c[2]]});
    }
  }
  for (const Tri& t : list) {
    if (turned_away(t)) continue;
    float xyz[9];
    for (int k = 0; k < 3; ++k) f(t.p[k], xyz + 3 * k);
    append(t, {xyz, xyz + 3, xyz + 6});
  }
  if (layer == Layer::kOverWall) {
    gl.Disable(GL_DEPTH_TEST);
  } else {
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthMask(layer == Layer::kSolid ? GL_TRUE : GL_FALSE);
    gl.DepthFunc(GL_LESS);
  }
  gl.VertexPointer(3, GL_FLOAT, 0, pos_.data());
  gl.ColorPointer(4, GL_FLOAT, 0, col_.data());
  gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(pos_.size() / 3));
}

// Walls first (depth written), then the sun on them painted over the walls without a depth test
// (the lit quads and the coarser wall triangles would z-fight: the mirror projection is not linear
// across a triangle), then everything standing in front, depth-tested against both.
void SceneMesh::draw_standing(const GlApi& gl, const FrameProjection& f, const WorldState& world, const RobotState& me, bool labels) {
  std::vector<Tri> tris;
  emit(gl, f, world, labels, {}, Layer::kSolid, -1.0, &walls_);
  for (const auto& sp : world.lighting.sun) {
    std::array<Eigen::Vector3d, 4> q;
    if (labels || sp.surface != SunPatch::Surface::kWall || !wall_patch_quad(sp, hx_, hy_, wall_height_, q)) continue;
    tris.clear();
    add_quad(tris, q[0], q[1], q[2], q[3], kWall, kLabelWall, 0.25);
    emit(gl, f, world, labels, tris, Layer::kOverWall, world.lighting.artificial_at(((q[0] + q[2]) / 2).head<2>()) + sp.strength);
  }
  tris.clear();
  for (const auto& r : world.robots)
    if (r.id != me.id) add_cylinder(tris, r.pose.translation(), r.radius, 0.0, r.height, kRobot, kLabelObstacle, 16, 5, &f.eye);
  if (world.has_ball)
    add_sphere(tris, Eigen::Vector3d(world.ball.position.x(), world.ball.position.y(), world.ball.radius), world.ball.radius, kBall, kLabelBall, f.eye);
  emit(gl, f, world, labels, tris, Layer::kSolid, -1.0, &statics_);
}

void SceneMesh::draw_floor_patches(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels) {
  std::vector<Tri> tris;
  for (const auto& fp : world.floor_patches) {
    const Eigen::Vector3f alb = fp.reflectance.cast<float>();
    const std::uint8_t lab = alb.maxCoeff() > 0.5f ? std::uint8_t{kLabelLine} : std::uint8_t{kLabelObstacle};
    const double ca = std::cos(fp.angle), sa = std::sin(fp.angle);
    auto corner = [&](double sx, double sy) {
      return Eigen::Vector3d(fp.centre.x() + ca * sx * fp.half_size.x() - sa * sy * fp.half_size.y(),
                             fp.centre.y() + sa * sx * fp.half_size.x() + ca * sy * fp.half_size.y(), 0.0);
    };
    add_quad(tris, corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1), alb, lab, 0.05);
  }
  if (!tris.empty()) emit(gl, f, world, labels, tris, Layer::kOnFloor);
}

// Drawn last without a depth test: nothing hides the body from its own camera.
void SceneMesh::draw_body(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels) {
  gl.Disable(GL_DEPTH_TEST);
  const float body_illum = static_cast<float>(world.lighting.at(f.pose.translation()) / kRadianceScale);
  pos_.clear();
  col_.clear();
  const int n = 64;
  const double rb = f.mirror.body_radius() * f.ss;
  for (int k = 0; k < n; ++k) {
    const double a0 = kTwoPi * k / n, a1 = kTwoPi * (k + 1) / n;
    const float cx = static_cast<float>(f.centre.x() * f.ss), cy = static_cast<float>(f.centre.y() * f.ss);
    pos_.insert(pos_.end(), {cx, cy, 0.0f, static_cast<float>(cx + rb * std::cos(a0)), static_cast<float>(cy + rb * std::sin(a0)), 0.0f,
                             static_cast<float>(cx + rb * std::cos(a1)), static_cast<float>(cy + rb * std::sin(a1)), 0.0f});
    for (int v = 0; v < 3; ++v) {
      if (labels) {
        const float l = static_cast<float>(kLabelBody) / 255.0f;
        col_.insert(col_.end(), {l, l, l, 1.0f});
      } else {
        col_.insert(col_.end(), {std::min(1.0f, kBody[0] * body_illum), std::min(1.0f, kBody[1] * body_illum),
                                 std::min(1.0f, kBody[2] * body_illum), 1.0f});
      }
    }
  }
  gl.VertexPointer(3, GL_FLOAT, 0, pos_.data());
  gl.ColorPointer(4, GL_FLOAT, 0, col_.data());
  gl.DrawArrays(GL_TRIANGLES, 0, n * 3);
}

}  // namespace omniloc::sim
