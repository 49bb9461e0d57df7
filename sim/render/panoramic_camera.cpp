#include "sim/render/panoramic_camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "sim/render/photometry.hpp"

namespace omniloc::sim {

namespace {

// Linear albedos (reflectances) of the scene's surfaces.
const Eigen::Vector3f kCarpet(0.10f, 0.34f, 0.12f);
const Eigen::Vector3f kLineWhite(0.85f, 0.85f, 0.85f);
const Eigen::Vector3f kHallFloor(0.30f, 0.29f, 0.27f);
const Eigen::Vector3f kWall(0.14f, 0.14f, 0.20f);
const Eigen::Vector3f kRobot(0.05f, 0.05f, 0.05f);
const Eigen::Vector3f kBall(0.85f, 0.30f, 0.05f);
const Eigen::Vector3f kPost(0.85f, 0.85f, 0.85f);
const Eigen::Vector3f kNet(0.50f, 0.52f, 0.50f);
const Eigen::Vector3f kBody(0.35f, 0.35f, 0.35f);
const Eigen::Vector3f kBlack(0.03f, 0.03f, 0.03f);

// Floor markings from a distance field: each texel holds the distance from its centre to the nearest
// marking's centre line (a 16-bit fraction of kDistanceRange metres). The shader takes the pixel's
// extent across the line from the screen-space change of that distance (fwidth) and returns the
// exact share of a pixel-wide box that the line covers. That anti-aliases far lines across the line
// only, where trilinear mip-mapping of a 1 cm RGBA texture blurred them by the pixel's largest
// extent in every direction, and costs one bilinear fetch per pixel instead of eight (the floor pass
// 1.3x faster on llvmpipe, docs/camera.md). Bilinear interpolation keeps the distance exact to a
// fraction of a millimetre where the field is linear in position, i.e. across a line's edges.
constexpr double kDistanceTexel = 0.02;  // metres
constexpr double kDistanceRange = 2.0;   // metres; farther is stored as 2 m
// Shared by the floor shaders: line, carpet, outside are albedos (label ids / 255 for labels).
const char* const kFloorCommon = R"(#version 130
uniform sampler2D distance_map;
uniform float range, half_width;
uniform vec3 line, carpet, outside;
float distance_to_line(vec2 uv) { return texture(distance_map, uv).r * range; }
// Share of a box as wide as the pixel's extent across the line that the line covers.
float line_cover(float d) {
  float fw = max(fwidth(d), 1e-4);
  return clamp((min(d + 0.5 * fw, half_width) - max(d - 0.5 * fw, -half_width)) / fw, 0.0, 1.0);
}
bool on_floor(vec2 uv) { return all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))); }
)";
const char* const kFloorShader = R"(
void main() {
  vec2 uv = gl_TexCoord[0].st;
  float cover = line_cover(distance_to_line(uv));
  gl_FragColor = vec4((on_floor(uv) ? mix(carpet, line, cover) : outside) * gl_Color.rgb, 1.0);
}
)";
// The same for triangles whose corners all lie on the floor inside the walls (most of them): the
// test of the texture coordinates cost 4 % of the frame.
const char* const kFloorShaderInside = R"(
void main() {
  gl_FragColor = vec4(mix(carpet, line, line_cover(distance_to_line(gl_TexCoord[0].st))) * gl_Color.rgb, 1.0);
}
)";
// The same field as flat class ids (a pixel is line where its centre is).
const char* const kFloorLabelShader = R"(
void main() {
  vec2 uv = gl_TexCoord[0].st;
  gl_FragColor = vec4(on_floor(uv) ? (distance_to_line(uv) <= half_width ? line : carpet) : outside, 1.0);
}
)";

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

struct Tri {
  std::array<Eigen::Vector3d, 3> p;  // world frame, metres
  Eigen::Vector3f albedo;
  std::uint8_t label;
  Eigen::Vector3d facing = Eigen::Vector3d::Zero();  // outward normal of a closed solid's face; zero: seen from both sides
};

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

// Triangles of the static scene with their corners as shared vertices, so that each vertex is
// projected through the mirror once per frame instead of once per triangle using it (a grid vertex
// is a corner of up to six).
struct SharedTris {
  std::vector<Tri> tris;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<unsigned, 3>> corners;  // per triangle, indices into vertices
};
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

}  // namespace

struct PanoramicCameraImpl {
  std::unique_ptr<GlContext> ctx;
  Field field;
  int ss = 2;                // supersampling factor
  int W = 0, H = 0;          // render size (W * ss ...)
  unsigned tex_distance = 0;           // floor distance field (kFloorShader)
  unsigned prog_floor = 0, prog_floor_inside = 0, prog_floor_labels = 0;
  double hx = 0, hy = 0;     // floor half extents covered by the texture
  // Polar floor mesh, fixed in the image.
  std::vector<float> mesh_xy;          // render-space positions
  std::vector<Eigen::Vector3d> mesh_dir;  // camera-frame unit ray of each vertex
  std::vector<unsigned> mesh_idx;
  SharedTris walls;                    // the hall's walls
  SharedTris statics;                  // goals, landmarks
  std::vector<unsigned char> readback;      // labels, RGBA8
  std::optional<Photometry> photometry;    // radiance to pixels, and the optics before it
  // Per-draw scratch.
  std::vector<float> pos, col, tex;
  std::vector<float> shared_xyz;       // this frame's projections of a SharedTris' vertices
  std::vector<std::uint8_t> hidden;    // per floor mesh vertex: bits 0-3 behind a wall, bit 4 off the floor inside the walls
  std::vector<unsigned> idx, idx_inside;  // floor triangles drawn this frame (all corners inside the walls)
};

PanoramicCamera::PanoramicCamera(const CameraConfig& config, const Field& field)
    : impl_(std::make_unique<PanoramicCameraImpl>()),
      cfg_(config),
      mirror_(MirrorProfile::preset(config.mirror, config.rim_px(), config.mount_height)) {
  PanoramicCameraImpl& m = *impl_;
  m.field = field;
  m.ss = cfg_.quality == "high" ? 2 : 1;
  m.W = cfg_.width * m.ss;
  m.H = cfg_.height * m.ss;
  m.ctx = make_gl_context(cfg_.backend);
  const GlApi& gl = m.ctx->gl();
  m.ctx->bind_framebuffer(m.W, m.H);

  // The floor's markings as a distance field (see kFloorShader): 2 cm texels over the floor inside
  // the walls, texel centres at uv = (i + 0.5) / size.
  m.hx = field.half_floor_x();
  m.hy = field.half_floor_y();
  const int tw = static_cast<int>(std::ceil(2 * m.hx / kDistanceTexel)), th = static_cast<int>(std::ceil(2 * m.hy / kDistanceTexel));
  std::vector<std::uint16_t> dist(static_cast<std::size_t>(tw) * th);
  for (int j = 0; j < th; ++j)
    for (int i = 0; i < tw; ++i) {
      const Eigen::Vector2d p(-m.hx + (i + 0.5) * 2 * m.hx / tw, -m.hy + (j + 0.5) * 2 * m.hy / th);
      const double d = std::min(field.distance_to_marking(p), kDistanceRange);
      dist[static_cast<std::size_t>(j) * tw + i] = static_cast<std::uint16_t>(std::lround(65535.0 * d / kDistanceRange));
    }
  gl.GenTextures(1, &m.tex_distance);
  gl.BindTexture(GL_TEXTURE_2D, m.tex_distance);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_R16, tw, th, 0, GL_RED, GL_UNSIGNED_SHORT, dist.data());
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + m.ctx->backend() + "\": floor distance texture upload failed");
  const double half_w = 0.5 * field.line_width;
  auto floor_program = [&](const char* body, const std::string& what, const Eigen::Vector3f& line, const Eigen::Vector3f& carpet,
                           const Eigen::Vector3f& outside) {
    const unsigned prog = m.ctx->fragment_program((std::string(kFloorCommon) + body).c_str(), what);
    gl.UseProgram(prog);
    gl.Uniform1i(gl.GetUniformLocation(prog, "distance_map"), 0);
    gl.Uniform1f(gl.GetUniformLocation(prog, "range"), static_cast<float>(kDistanceRange));
    gl.Uniform1f(gl.GetUniformLocation(prog, "half_width"), static_cast<float>(half_w));
    gl.Uniform3f(gl.GetUniformLocation(prog, "line"), line[0], line[1], line[2]);
    gl.Uniform3f(gl.GetUniformLocation(prog, "carpet"), carpet[0], carpet[1], carpet[2]);
    gl.Uniform3f(gl.GetUniformLocation(prog, "outside"), outside[0], outside[1], outside[2]);
    gl.UseProgram(0);
    if (gl.GetError() != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + m.ctx->backend() + "\": " + what + " shader set-up failed");
    return prog;
  };
  m.prog_floor = floor_program(kFloorShader, "floor", kLineWhite, kCarpet, kHallFloor);
  m.prog_floor_inside = floor_program(kFloorShaderInside, "floor (inside the walls)", kLineWhite, kCarpet, kHallFloor);
  auto label = [](LabelClass l) { return Eigen::Vector3f::Constant(static_cast<float>(l) / 255.0f); };
  m.prog_floor_labels = floor_program(kFloorLabelShader, "floor label", label(kLabelLine), label(kLabelField), label(kLabelFloorOutside));

  // Polar floor mesh in render space. Texture coordinates are interpolated linearly across each
  // cell, so rings are placed where the floor distance stops being linear in the image radius: a
  // new ring whenever the midpoint of the floor distance deviates by more than `tol` from the chord
  // (the mirror's isometric part needs few rings, the inner and outer parts many), and each ring
  // has the fewest sectors whose chord strays at most `tol` from the arc on the floor (few near
  // the robot, 128 at 8 m). llvmpipe's cost per triangle is a large share of the frame: the
  // default mesh has about 2900 triangles where a fixed 120 sectors made 6720 (docs/camera.md).
  const double tol = cfg_.quality == "low" ? 0.01 : 0.003;
  auto floor_dist = [&](double r) {
    const double e = mirror_.elevation(std::clamp(r, mirror_.body_radius(), mirror_.rim()));
    return e < -1e-3 ? cfg_.mount_height / std::tan(-e) : 1e3;
  };
  std::vector<double> radii;
  double r0 = mirror_.body_radius() - 1.0;
  radii.push_back(r0);
  while (r0 < mirror_.rim() + 1.0) {
    // Up to 30 m (beyond, the far floor is one colour). Where a pixel spans more than 5 cm of
    // floor (beyond the calibrated 8 m at the default mirror, no line points are taken there)
    // within half a pixel, else within `tol` or a tenth of a pixel: the far band's thin rings cost
    // 0.8 ms per frame at a tenth of a pixel (docs/camera.md).
    double step = 32.0;
    while (step > 0.5) {
      const double a = floor_dist(r0), b = floor_dist(r0 + step), mid = floor_dist(r0 + 0.5 * step);
      const double m_per_px = (b - a) / step;
      if (a > 30.0 || (b <= 30.0 && std::fabs(mid - 0.5 * (a + b)) <= std::max(tol, (m_per_px > 0.05 ? 0.5 : 0.1) * m_per_px))) break;
      step *= 0.5;
    }
    r0 = std::min(r0 + step, mirror_.rim() + 1.0);
    radii.push_back(r0);
    if (r0 >= mirror_.rim() + 1.0) break;
  }
  const Eigen::Vector2d c = centre();
  std::vector<unsigned> ring_start;
  std::vector<int> ring_sectors;
  int sectors = 16;
  for (double r : radii) {
    const double R = std::min(floor_dist(r), 30.0);  // beyond: the hall's far floor, one colour
    while (sectors < 128 && R * (1.0 - std::cos(kPi / sectors)) > tol) sectors *= 2;
    ring_start.push_back(static_cast<unsigned>(m.mesh_dir.size()));
    ring_sectors.push_back(sectors);
    const double e = mirror_.elevation(std::clamp(r, mirror_.body_radius(), mirror_.rim()));
    for (int k = 0; k <= sectors; ++k) {
      const double b = kTwoPi * k / sectors;
      m.mesh_xy.push_back(static_cast<float>((c.x() - r * std::sin(b)) * m.ss));
      m.mesh_xy.push_back(static_cast<float>((c.y() - r * std::cos(b)) * m.ss));
      m.mesh_dir.emplace_back(std::cos(e) * std::cos(b), std::cos(e) * std::sin(b), std::sin(e));
    }
  }
  // Neighbouring rings zipped together by angle (an outer ring has as many sectors or more).
  for (std::size_t i = 0; i + 1 < radii.size(); ++i) {
    const unsigned na = static_cast<unsigned>(ring_sectors[i]), nb = static_cast<unsigned>(ring_sectors[i + 1]);
    unsigned ka = 0, kb = 0;
    while (ka < na || kb < nb) {
      const unsigned a = ring_start[i] + ka, b = ring_start[i + 1] + kb;
      // Advance on the ring whose next vertex comes first (ka / na against kb / nb, exactly).
      if (kb == nb || (ka < na && (ka + 1) * nb <= (kb + 1) * na)) {
        m.mesh_idx.insert(m.mesh_idx.end(), {a, a + 1, b});
        ++ka;
      } else {
        m.mesh_idx.insert(m.mesh_idx.end(), {a, b + 1, b});
        ++kb;
      }
    }
  }

  // Static scene: walls, goals, landmarks.
  std::vector<Tri> wall_tris, static_tris;
  const double wall_t = 0.1, wh = field.wall_height;
  if (wh > 0) {
    // Only what can be seen from inside the hall: each wall's inner face and its top.
    const double ex = m.hx + 2 * wall_t;
    auto wall = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& out) {
      const Eigen::Vector2d a2 = a + 2 * wall_t * out, b2 = b + 2 * wall_t * out;
      add_quad(wall_tris, {a.x(), a.y(), 0}, {b.x(), b.y(), 0}, {b.x(), b.y(), wh}, {a.x(), a.y(), wh}, kWall, kLabelWall, 0.6);
      add_quad(wall_tris, {a.x(), a.y(), wh}, {b.x(), b.y(), wh}, {b2.x(), b2.y(), wh}, {a2.x(), a2.y(), wh}, kWall, kLabelWall, 0.6);
    };
    wall({-ex, m.hy}, {ex, m.hy}, {0, 1});
    wall({-ex, -m.hy}, {ex, -m.hy}, {0, -1});
    wall({m.hx, -m.hy}, {m.hx, m.hy}, {1, 0});
    wall({-m.hx, -m.hy}, {-m.hx, m.hy}, {-1, 0});
  }
  for (const auto& g : field.goals) {
    const bool coloured = g.colour != "white";
    const Eigen::Vector3f post = coloured ? colour_of(g.colour) : kPost;
    const std::uint8_t plab = coloured ? label_of(g.colour) : std::uint8_t{kLabelGoal};
    const double hp = 0.5 * g.post_width, s = g.side();
    for (const Eigen::Vector2d& pp : {g.left_post(), g.right_post()}) add_box(static_tris, pp, hp, hp, 0, 0, g.height, post, plab, 0.15);
    const double yw = 0.5 * g.width + g.post_width;
    add_box(static_tris, {g.goal_line_x, 0}, hp, yw, 0, g.height - g.post_width, g.height, post, plab, 0.15);
    // Net: back and side panels (coloured inside on the legacy field).
    const Eigen::Vector3f net = coloured ? colour_of(g.colour) : kNet;
    const std::uint8_t nlab = coloured ? label_of(g.colour) : std::uint8_t{kLabelGoal};
    const double x0 = g.goal_line_x + s * hp, x1 = g.goal_line_x + s * g.depth;
    add_quad(static_tris, {x1, -yw, 0}, {x1, yw, 0}, {x1, yw, g.height}, {x1, -yw, g.height}, net, nlab, 0.2);
    add_quad(static_tris, {x0, -yw, 0}, {x1, -yw, 0}, {x1, -yw, g.height}, {x0, -yw, g.height}, net, nlab, 0.2);
    add_quad(static_tris, {x0, yw, 0}, {x1, yw, 0}, {x1, yw, g.height}, {x0, yw, g.height}, net, nlab, 0.2);
    add_quad(static_tris, {x0, -yw, g.height}, {x1, -yw, g.height}, {x1, yw, g.height}, {x0, yw, g.height}, net, nlab, 0.2);
  }
  for (const auto& l : field.landmarks) {
    if (l.shape == "post")
      add_cylinder(static_tris, l.position, 0.5 * l.size, 0, l.height, colour_of(l.colour), label_of(l.colour), 16, 6);
    else
      add_box(static_tris, l.position, 0.5 * l.size, 0.5 * l.size, 0, 0, l.height, colour_of(l.colour), label_of(l.colour), 0.1);
  }
  m.walls = share_vertices(std::move(wall_tris));
  m.statics = share_vertices(std::move(static_tris));

  m.photometry.emplace(cfg_, mirror_, m.ss);
}

PanoramicCamera::~PanoramicCamera() {
  if (impl_ && impl_->ctx) {
    impl_->ctx->make_current();
    impl_->ctx->gl().DeleteTextures(1, &impl_->tex_distance);
    impl_->ctx->gl().DeleteProgram(impl_->prog_floor);
    impl_->ctx->gl().DeleteProgram(impl_->prog_floor_inside);
    impl_->ctx->gl().DeleteProgram(impl_->prog_floor_labels);
  }
}

const std::string& PanoramicCamera::backend() const { return impl_->ctx->backend(); }

Eigen::Vector2d PanoramicCamera::centre() const {
  return cfg_.mirror_centre_px();
}

double PanoramicCamera::response(double albedo, double illumination, const CameraSettings& s) {
  return kResponse * albedo * illumination * s.exposure_ms * s.gain;
}

CameraSettings PanoramicCamera::clamp(const CameraSettings& s, bool* clamped) const {
  CameraSettings o;
  o.exposure_ms = std::clamp(s.exposure_ms, cfg_.exposure_min, cfg_.exposure_max);
  o.gain = std::clamp(s.gain, cfg_.gain_min, cfg_.gain_max);
  if (!std::isfinite(s.exposure_ms)) o.exposure_ms = cfg_.exposure_min;
  if (!std::isfinite(s.gain)) o.gain = cfg_.gain_min;
  if (clamped) *clamped = o.exposure_ms != s.exposure_ms || o.gain != s.gain;
  return o;
}

namespace {

// Camera-to-robot rotation: fixed mirror tilt about x, plus per-frame vibration (roll, pitch).
Eigen::Matrix3d camera_rotation(double roll, double pitch) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  Eigen::Matrix3d rx, ry;
  rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  return rx * ry;
}

}  // namespace

std::optional<Eigen::Vector2d> PanoramicCamera::project(const Eigen::Vector3d& p) const {
  const Eigen::Matrix3d R = camera_rotation(cfg_.mirror_tilt, 0.0);
  const Eigen::Vector3d q = R.transpose() * (p - Eigen::Vector3d(0, 0, cfg_.mount_height));
  const double rho = std::hypot(q.x(), q.y());
  if (rho < 1e-9) return std::nullopt;
  const double e = std::atan2(q.z(), rho), b = std::atan2(q.y(), q.x());
  const double r = mirror_.radius(e);
  if (r < mirror_.body_radius() || r > mirror_.rim()) return std::nullopt;
  return centre() + r * Eigen::Vector2d(-std::sin(b), -std::cos(b));
}

std::optional<Eigen::Vector2d> PanoramicCamera::floor_point(double u, double v) const {
  const Eigen::Vector2d d = Eigen::Vector2d(u, v) - centre();
  const double r = d.norm();
  if (r < mirror_.body_radius() || r > mirror_.rim()) return std::nullopt;
  const double e = mirror_.elevation(r), b = std::atan2(-d.x(), -d.y());
  const Eigen::Vector3d dir = camera_rotation(cfg_.mirror_tilt, 0.0) * Eigen::Vector3d(std::cos(e) * std::cos(b), std::cos(e) * std::sin(b), std::sin(e));
  if (dir.z() >= -1e-9) return std::nullopt;
  const double t = cfg_.mount_height / -dir.z();
  return Eigen::Vector2d(t * dir.x(), t * dir.y());
}

namespace {

// Texture coordinates in the floor's distance field of a world floor point (metres).
void floor_uv(const PanoramicCameraImpl& m, const Eigen::Vector2d& w, float* uv) {
  uv[0] = static_cast<float>((w.x() + m.hx) / (2 * m.hx));
  uv[1] = static_cast<float>((w.y() + m.hy) / (2 * m.hy));
}

// One draw of the scene into the bound framebuffer. `labels`: flat class colours, no lighting.
void draw_scene(PanoramicCameraImpl& m, const CameraConfig& cfg, const MirrorProfile& mirror, const Eigen::Vector2d& centre,
                const WorldState& world, const RobotState& me, const Eigen::Matrix3d& R, bool labels) {
  const GlApi& gl = m.ctx->gl();
  const Pose2& pose = me.pose;
  const double h = cfg.mount_height;
  gl.Viewport(0, 0, m.W, m.H);
  gl.MatrixMode(GL_PROJECTION);
  gl.LoadIdentity();
  gl.Ortho(0, m.W, m.H, 0, 0.0, 1000.0);  // render space: x right, y down; z = -depth
  gl.MatrixMode(GL_MODELVIEW);
  gl.LoadIdentity();
  gl.ShadeModel(GL_SMOOTH);
  // Above the walls: the hall, seen as its far floor under the light at the robot (the floor mesh
  // skips the rays that miss the floor).
  const Eigen::Vector3f bg = labels ? Eigen::Vector3f::Constant(static_cast<float>(kLabelFloorOutside) / 255.0f)
                                    : Eigen::Vector3f(kHallFloor * (world.lighting.artificial_at(pose.translation()) / kRadianceScale));
  gl.ClearColor(bg[0], bg[1], bg[2], 1.0f);
  gl.DepthMask(GL_TRUE);  // the clear writes depth only through the mask (the floor leaves it off)
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.EnableClientState(GL_COLOR_ARRAY);

  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  // Everything standing: triangles projected per vertex through the mirror.
  const Eigen::Matrix3d Rt = R.transpose();
  auto project = [&](const Eigen::Vector3d& wp, float* out) {
    const double dx = wp.x() - pose.x, dy = wp.y() - pose.y;
    const Eigen::Vector3d q = Rt * Eigen::Vector3d(c * dx + s * dy, -s * dx + c * dy, wp.z() - h);
    const double rho = std::max(std::hypot(q.x(), q.y()), 1e-9);
    const double k = mirror.radius(std::atan2(q.z(), rho)) / rho;  // bearing b: (cos b, sin b) = (q.x, q.y) / rho
    out[0] = static_cast<float>((centre.x() - k * q.y()) * m.ss);
    out[1] = static_cast<float>((centre.y() - k * q.x()) * m.ss);
    out[2] = static_cast<float>(-std::min(999.0, q.norm()));
  };
  std::vector<Tri> tris;
  // fixed_light >= 0: every triangle under that illumination instead of the floor light at its middle.
  // kSolid: depth-tested and written; kOverWall: painted without a test; kOnFloor: at the far plane,
  // tested, not written (under everything standing).
  enum class Layer { kSolid, kOverWall, kOnFloor };
  const Eigen::Vector3d eye(pose.x, pose.y, h);  // the camera, world frame (vibration aside)
  // `shared` (optional): drawn first, each of its vertices projected once.
  auto emit_all = [&](const std::vector<Tri>& list, Layer layer, double fixed_light = -1.0, const SharedTris* shared = nullptr) {
    m.pos.clear();
    m.col.clear();
    auto append = [&](const Tri& t, const std::array<const float*, 3>& corners) {
      const Eigen::Vector2d mid = (t.p[0].head<2>() + t.p[1].head<2>() + t.p[2].head<2>()) / 3.0;
      const float illum = static_cast<float>((fixed_light >= 0 ? fixed_light : world.lighting.at(mid)) / kRadianceScale);
      for (const float* xyz : corners) {
        m.pos.insert(m.pos.end(), {xyz[0], xyz[1], layer == Layer::kOnFloor ? -999.0f : xyz[2]});
        if (labels) {
          const float l = t.label / 255.0f;
          m.col.insert(m.col.end(), {l, l, l, 1.0f});
        } else {
          m.col.insert(m.col.end(), {std::min(1.0f, t.albedo[0] * illum), std::min(1.0f, t.albedo[1] * illum),
                                     std::min(1.0f, t.albedo[2] * illum), 1.0f});
        }
      }
    };
    // A face of a solid turned away from the eye is hidden behind the solid.
    auto turned_away = [&](const Tri& t) { return t.facing.dot(eye - t.p[0]) < 0; };
    if (shared) {
      m.shared_xyz.resize(3 * shared->vertices.size());
      for (std::size_t i = 0; i < shared->vertices.size(); ++i) project(shared->vertices[i], &m.shared_xyz[3 * i]);
      for (std::size_t k = 0; k < shared->tris.size(); ++k) {
        if (turned_away(shared->tris[k])) continue;
        const auto& c = shared->corners[k];
        append(shared->tris[k], {&m.shared_xyz[3 * c[0]], &m.shared_xyz[3 * c[1]], &m.shared_xyz[3 * c[2]]});
      }
    }
    for (const Tri& t : list) {
      if (turned_away(t)) continue;
      float xyz[9];
      for (int k = 0; k < 3; ++k) project(t.p[k], xyz + 3 * k);
      append(t, {xyz, xyz + 3, xyz + 6});
    }
    if (layer == Layer::kOverWall) {
      gl.Disable(GL_DEPTH_TEST);
    } else {
      gl.Enable(GL_DEPTH_TEST);
      gl.DepthMask(layer == Layer::kSolid ? GL_TRUE : GL_FALSE);
      gl.DepthFunc(GL_LESS);
    }
    gl.VertexPointer(3, GL_FLOAT, 0, m.pos.data());
    gl.ColorPointer(4, GL_FLOAT, 0, m.col.data());
    gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(m.pos.size() / 3));
  };
  // Walls first (depth written), then the sun on them painted over the walls without a depth test
  // (the lit quads and the coarser wall triangles would z-fight: the mirror projection is not linear
  // across a triangle), then everything standing in front, depth-tested against both.
  emit_all({}, Layer::kSolid, -1.0, &m.walls);
  for (const auto& sp : world.lighting.sun) {
    std::array<Eigen::Vector3d, 4> q;
    if (labels || sp.surface != SunPatch::Surface::kWall || !wall_patch_quad(sp, m.hx, m.hy, m.field.wall_height, q)) continue;
    tris.clear();
    add_quad(tris, q[0], q[1], q[2], q[3], kWall, kLabelWall, 0.25);
    emit_all(tris, Layer::kOverWall, world.lighting.artificial_at(((q[0] + q[2]) / 2).head<2>()) + sp.strength);
  }
  tris.clear();
  for (const auto& r : world.robots)
    if (r.id != me.id) add_cylinder(tris, r.pose.translation(), r.radius, 0.0, r.height, kRobot, kLabelObstacle, 16, 5, &eye);
  if (world.has_ball)
    add_sphere(tris, Eigen::Vector3d(world.ball.position.x(), world.ball.position.y(), world.ball.radius), world.ball.radius, kBall, kLabelBall, eye);
  emit_all(tris, Layer::kSolid, -1.0, &m.statics);

  // Floor, after everything standing on it: depth-tested at the far plane (written by nothing), so
  // llvmpipe skips the floor shader where walls and robots cover it. Texture coordinates are this
  // frame's floor points of the image-fixed rays. Each vertex
  // also gets a bit per hall wall that hides its floor point (bits 0-3: beyond x = hx, x = -hx,
  // y = hy, y = -hy and below the line of sight over that wall) and all bits when its ray misses
  // the floor; a triangle whose vertices share a bit is not drawn, as the wall is drawn over it or
  // nothing of the floor is there (the rasteriser's fill is the renderer's largest cost).
  const std::size_t nv = m.mesh_dir.size();
  m.pos.resize(nv * 3);
  m.col.resize(nv * 4);
  m.tex.resize(nv * 2);
  m.hidden.resize(nv);
  const double keep = m.field.wall_height > 0 ? 1.0 - std::min(1.0, m.field.wall_height / h) : 2.0;  // hidden beyond a wall at t > keep
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3d d = R * m.mesh_dir[i];
    Eigen::Vector2d w;
    std::uint8_t hidden = 0;
    if (d.z() < -1e-6) {
      const double t = h / -d.z();
      const double rx = t * d.x(), ry = t * d.y();
      w = {pose.x + c * rx - s * ry, pose.y + s * rx + c * ry};
      // The wall plane at fraction t_w of the way to the floor point hides it when t_w > keep.
      auto behind = [&](double wall, double p, double f) { return std::fabs(wall - p) > keep * std::fabs(f - p); };
      if (w.x() > m.hx && behind(m.hx, pose.x, w.x())) hidden |= 1;
      if (w.x() < -m.hx && behind(-m.hx, pose.x, w.x())) hidden |= 2;
      if (w.y() > m.hy && behind(m.hy, pose.y, w.y())) hidden |= 4;
      if (w.y() < -m.hy && behind(-m.hy, pose.y, w.y())) hidden |= 8;
    } else {
      w = {pose.x + 1e4 * (c * d.x() - s * d.y()), pose.y + 1e4 * (s * d.x() + c * d.y())};  // no floor: far beyond the walls
      hidden = 15;
    }
    if (std::fabs(w.x()) > m.hx || std::fabs(w.y()) > m.hy) hidden |= 16;  // not on the floor inside the walls
    m.hidden[i] = hidden;
    m.pos[3 * i] = m.mesh_xy[2 * i];
    m.pos[3 * i + 1] = m.mesh_xy[2 * i + 1];
    m.pos[3 * i + 2] = -999.0f;
    floor_uv(m, w, &m.tex[2 * i]);
    // The lamps' light only: sun beams are drawn over this below, with sharp edges.
    const float illum = labels ? 1.0f : static_cast<float>(std::min(1.0, world.lighting.artificial_at(w) / kRadianceScale));
    m.col[4 * i] = m.col[4 * i + 1] = m.col[4 * i + 2] = illum;
    m.col[4 * i + 3] = 1.0f;
  }
  m.idx.clear();
  m.idx_inside.clear();
  for (std::size_t t = 0; t < m.mesh_idx.size(); t += 3) {
    const unsigned a = m.mesh_idx[t], b = m.mesh_idx[t + 1], cc = m.mesh_idx[t + 2];
    if ((m.hidden[a] & m.hidden[b] & m.hidden[cc] & 15) != 0) continue;
    auto& list = labels || ((m.hidden[a] | m.hidden[b] | m.hidden[cc]) & 16) ? m.idx : m.idx_inside;
    list.insert(list.end(), {a, b, cc});
  }
  gl.Enable(GL_DEPTH_TEST);  // behind walls and robots drawn before: not shaded
  gl.DepthMask(GL_FALSE);
  gl.DepthFunc(GL_LESS);
  gl.BindTexture(GL_TEXTURE_2D, m.tex_distance);
  gl.UseProgram(labels ? m.prog_floor_labels : m.prog_floor);
  gl.EnableClientState(GL_TEXTURE_COORD_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, m.pos.data());
  gl.ColorPointer(4, GL_FLOAT, 0, m.col.data());
  gl.TexCoordPointer(2, GL_FLOAT, 0, m.tex.data());
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.idx.size()), GL_UNSIGNED_INT, m.idx.data());
  if (!m.idx_inside.empty()) {
    gl.UseProgram(m.prog_floor_inside);
    gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.idx_inside.size()), GL_UNSIGNED_INT, m.idx_inside.data());
  }
  gl.DisableClientState(GL_TEXTURE_COORD_ARRAY);
  gl.UseProgram(0);

  // Sun beams on the carpet: the floor under each beam drawn again with the floor shader under the
  // beam's light, in cells of at most 0.1 m projected through the mirror, so a patch's edges are as
  // sharp as the pixels (a per-vertex light on the image-fixed floor mesh would smear them over a
  // mesh cell).
  if (!labels) {
    gl.UseProgram(m.prog_floor);
    gl.EnableClientState(GL_TEXTURE_COORD_ARRAY);
    for (const auto& sp : world.lighting.sun) {
      if (sp.surface != SunPatch::Surface::kFloor) continue;
      const double x0 = std::max(-m.hx, sp.centre.x() - sp.half_size.x()), x1 = std::min(m.hx, sp.centre.x() + sp.half_size.x());
      const double y0 = std::max(-m.hy, sp.centre.y() - sp.half_size.y()), y1 = std::min(m.hy, sp.centre.y() + sp.half_size.y());
      if (x1 <= x0 || y1 <= y0) continue;
      const int nx = std::max(1, static_cast<int>(std::ceil((x1 - x0) / 0.1))), ny = std::max(1, static_cast<int>(std::ceil((y1 - y0) / 0.1)));
      m.pos.clear();
      m.col.clear();
      m.tex.clear();
      auto vertex = [&](int i, int j) {
        const Eigen::Vector2d w(x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny);
        float xyz[3];
        project(Eigen::Vector3d(w.x(), w.y(), 0.0), xyz);
        m.pos.insert(m.pos.end(), {xyz[0], xyz[1], -999.0f});
        float uv[2];
        floor_uv(m, w, uv);
        m.tex.insert(m.tex.end(), uv, uv + 2);
        const float il = static_cast<float>(std::min(1.0, world.lighting.at(w) / kRadianceScale));
        m.col.insert(m.col.end(), {il, il, il, 1.0f});
      };
      for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j)
          for (const auto& [a, b] : std::array<std::pair<int, int>, 6>{{{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j}, {i + 1, j + 1}, {i, j + 1}}})
            vertex(a, b);
      gl.VertexPointer(3, GL_FLOAT, 0, m.pos.data());
      gl.ColorPointer(4, GL_FLOAT, 0, m.col.data());
      gl.TexCoordPointer(2, GL_FLOAT, 0, m.tex.data());
      gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(m.pos.size() / 3));
    }
    gl.DisableClientState(GL_TEXTURE_COORD_ARRAY);
    gl.UseProgram(0);
  }
  // Floor patches lie on the carpet: drawn over the floor, under everything standing on it.
  tris.clear();
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
  if (!tris.empty()) emit_all(tris, Layer::kOnFloor);

  // The robot's own body in the image centre (its brightness follows the light on the robot).
  gl.Disable(GL_DEPTH_TEST);
  const float body_illum = static_cast<float>(world.lighting.at(pose.translation()) / kRadianceScale);
  m.pos.clear();
  m.col.clear();
  const int n = 64;
  const double rb = mirror.body_radius() * m.ss;
  for (int k = 0; k < n; ++k) {
    const double a0 = kTwoPi * k / n, a1 = kTwoPi * (k + 1) / n;
    const float cx = static_cast<float>(centre.x() * m.ss), cy = static_cast<float>(centre.y() * m.ss);
    m.pos.insert(m.pos.end(), {cx, cy, 0.0f, static_cast<float>(cx + rb * std::cos(a0)), static_cast<float>(cy + rb * std::sin(a0)), 0.0f,
                               static_cast<float>(cx + rb * std::cos(a1)), static_cast<float>(cy + rb * std::sin(a1)), 0.0f});
    for (int v = 0; v < 3; ++v) {
      if (labels) {
        const float l = static_cast<float>(kLabelBody) / 255.0f;
        m.col.insert(m.col.end(), {l, l, l, 1.0f});
      } else {
        m.col.insert(m.col.end(), {std::min(1.0f, kBody[0] * body_illum), std::min(1.0f, kBody[1] * body_illum),
                                   std::min(1.0f, kBody[2] * body_illum), 1.0f});
      }
    }
  }
  gl.VertexPointer(3, GL_FLOAT, 0, m.pos.data());
  gl.ColorPointer(4, GL_FLOAT, 0, m.col.data());
  gl.DrawArrays(GL_TRIANGLES, 0, n * 3);
  gl.DisableClientState(GL_COLOR_ARRAY);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.Finish();
}

}  // namespace

Image PanoramicCamera::render(const WorldState& world, int robot_id, const CameraSettings& requested, Rng& rng) {
  PanoramicCameraImpl& m = *impl_;
  const RobotState* me = world.robot(robot_id);
  if (!me) throw RuntimeFailure("render: no robot with id " + std::to_string(robot_id));
  const CameraSettings st = clamp(requested);
  m.photometry->draw_noise_table(rng);  // first: the order of the draws from `rng` shapes every frame after
  // Tilt: per-frame vibration plus the body's pitch and roll on its suspension under the drive's
  // acceleration (forward acceleration tips the top backwards, acceleration to the left tips it
  // to the right; docs/camera.md "Tilt").
  const Eigen::Vector2d acc = Pose2(0, 0, me->pose.theta).inverse_transform(me->acceleration);
  const double roll = cfg_.mirror_tilt + (cfg_.vibration_std > 0 ? rng.normal(0.0, cfg_.vibration_std) : 0.0) + cfg_.tilt_per_accel * acc.y();
  const double pitch = (cfg_.vibration_std > 0 ? rng.normal(0.0, cfg_.vibration_std) : 0.0) - cfg_.tilt_per_accel * acc.x();
  const std::uint64_t off = rng.next_u64();

  m.ctx->make_current();
  m.ctx->bind_framebuffer(m.W, m.H);
  const Eigen::Matrix3d R = camera_rotation(roll, pitch);
  // Motion blur: the sensor integrates over the exposure [t - T, t]. Translation (of this robot and
  // everything else moving) by sub-frames along constant velocities, as many as the fastest image
  // motion needs at the floor's finest sampling; this robot's rotation about the mirror axis as an
  // exact polar smear of omega * T below.
  const double exposure_s = cfg_.motion_blur ? 1e-3 * st.exposure_ms : 0.0;
  const int subframes = m.photometry->subframes(me->velocity.norm(), exposure_s);
  if (subframes == 1) {
    draw_scene(m, cfg_, mirror_, centre(), world, *me, R, false);
    m.ctx->read_rgba16(m.photometry->radiance());
  } else {
    m.photometry->clear_sum();
    for (int k = 0; k < subframes; ++k) {
      const double back = exposure_s * (1.0 - (k + 0.5) / subframes);  // seconds before t
      WorldState w = world;
      for (auto& r : w.robots) r.pose = Pose2(r.pose.x - back * r.velocity.x(), r.pose.y - back * r.velocity.y(), r.pose.theta);
      w.ball.position -= back * w.ball.velocity;
      draw_scene(m, cfg_, mirror_, centre(), w, *w.robot(robot_id), R, false);
      m.ctx->read_rgba16(m.photometry->subframe());
      m.photometry->add_subframe();
    }
    m.photometry->average(subframes);
  }
  // Over the exposure the robot turned by omega * T; the image at time t - s is the final one turned
  // back by omega * s about the mirror axis (robot forward up, left left: a left turn moves the
  // scene clockwise on the image).
  m.photometry->apply_optics(me->omega * exposure_s);
  return m.photometry->expose(st, off);
}

Image PanoramicCamera::render_labels(const WorldState& world, int robot_id) {
  PanoramicCameraImpl& m = *impl_;
  const RobotState* me = world.robot(robot_id);
  if (!me) throw RuntimeFailure("render_labels: no robot with id " + std::to_string(robot_id));
  m.ctx->make_current();
  m.ctx->bind_framebuffer(m.W, m.H);
  draw_scene(m, cfg_, mirror_, centre(), world, *me, camera_rotation(cfg_.mirror_tilt, 0.0), true);
  m.ctx->read_rgba(m.readback);
  Image img;
  img.width = cfg_.width;
  img.height = cfg_.height;
  img.rgb.resize(static_cast<std::size_t>(img.width) * img.height * 3);
  const Eigen::Vector2d c = centre();
  const double rim2 = mirror_.rim() * mirror_.rim();
  for (int v = 0; v < img.height; ++v) {
    std::uint8_t* out = img.row(v);
    const double dv = v + 0.5 - c.y();
    // The sample nearest the output pixel centre of the supersampled grid.
    const int gy = m.H - 1 - (v * m.ss + m.ss / 2);
    for (int u = 0; u < img.width; ++u) {
      const double du = u + 0.5 - c.x();
      const std::uint8_t l = du * du + dv * dv > rim2 ? std::uint8_t{kLabelUnknown} : m.readback[(static_cast<std::size_t>(gy) * m.W + u * m.ss + m.ss / 2) * 4];
      out[3 * u] = out[3 * u + 1] = out[3 * u + 2] = l;
    }
  }
  return img;
}

}  // namespace omniloc::sim
