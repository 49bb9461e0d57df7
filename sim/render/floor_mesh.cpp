// The floor mesh, its distance field and shaders (see floor_mesh.hpp). Units: metres, radians;
// frames: world, camera (mesh rays), render space (the supersampled image, pixels).
#include "sim/render/floor_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "sim/render/label_class.hpp"
#include "sim/render/photometry.hpp"

namespace omniloc::sim {

namespace {

// Linear albedos (reflectances) of the floor.
const Eigen::Vector3f kCarpet(0.10f, 0.34f, 0.12f);
const Eigen::Vector3f kLineWhite(0.85f, 0.85f, 0.85f);
const Eigen::Vector3f kHallFloor(0.30f, 0.29f, 0.27f);

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
// The pixel's extent is fwidthCoarse where GL_ARB_derivative_control exists: one derivative per 2 x 2
// quad, which is what llvmpipe's fwidth is (OSMesa's bytes are the same either way), whereas NVIDIA's
// plain fwidth is finer and gave 0.4-0.5 % fewer line points per frame than OSMesa, 4 seed-to-seed
// standard deviations; with fwidthCoarse the H200's runs match OSMesa's (docs/performance.md "GPUs").
//
// The floor point of each pixel is found per pixel, not interpolated from the mesh's vertices: the
// floor position is not affine in the image (it holds D(r) p / |p|, D the floor distance at image
// radius r, whose chord over a mesh cell strays from the curve), and the vertices' floor points
// interpolated across the mesh's long cells drew lines up to 1 cm nearer the robot at 1-2 m than
// the mirror puts them (tests/camera_test.cpp FloorLinesLieWhereTheMirrorPutsThem). gl_TexCoord[0]
// is the fragment's render-space position (exact under affine interpolation); the elevation comes
// from a table of the mirror's law every 1/16 px (linear interpolation: well under a millimetre).
const char* const kFloorCommon = R"(#version 130
#extension GL_ARB_derivative_control : enable
uniform sampler2D distance_map;
uniform sampler2D elevation_map;
uniform float range, half_width;
uniform vec3 line, carpet, outside;
uniform float elev_lo, elev_step, elev_n, body_px, rim_px, inv_ss, eye_height;
uniform vec2 centre_rs, floor_half;
uniform vec3 cam_r0, cam_r1, cam_r2;
uniform vec4 robot;
float distance_to_line(vec2 uv) { return texture(distance_map, uv).r * range; }
// Render-space position to the distance field's texture coordinates of the floor point seen there
// (outside [0, 1] where the ray misses the floor).
vec2 floor_uv_at(vec2 rs) {
  vec2 p = (rs - centre_rs) * inv_ss;
  float len = max(length(p), 1e-4);
  float r = clamp(len, body_px, rim_px);
  float e = texture(elevation_map, vec2(((r - elev_lo) / elev_step + 0.5) / elev_n, 0.5)).r;
  vec2 sc = -p / len;  // (sin b, cos b): the image's x = cx - r sin b, y = cy - r cos b
  vec3 dc = vec3(cos(e) * sc.y, cos(e) * sc.x, sin(e));
  vec3 d = vec3(dot(cam_r0, dc), dot(cam_r1, dc), dot(cam_r2, dc));
  if (d.z > -1e-6) return vec2(-1.0);
  vec2 q = (eye_height / -d.z) * d.xy;
  vec2 w = robot.xy + vec2(robot.z * q.x - robot.w * q.y, robot.w * q.x + robot.z * q.y);
  return (w + floor_half) / (2.0 * floor_half);
}
// Share of a box as wide as the pixel's extent across the line that the line covers.
float line_cover(float d) {
#ifdef GL_ARB_derivative_control
  float fw = max(fwidthCoarse(d), 1e-4);
#else
  float fw = max(fwidth(d), 1e-4);
#endif
  return clamp((min(d + 0.5 * fw, half_width) - max(d - 0.5 * fw, -half_width)) / fw, 0.0, 1.0);
}
bool on_floor(vec2 uv) { return all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))); }
)";
const char* const kFloorShader = R"(
void main() {
  vec2 uv = floor_uv_at(gl_TexCoord[0].st);
  float cover = line_cover(distance_to_line(uv));
  gl_FragColor = vec4((on_floor(uv) ? mix(carpet, line, cover) : outside) * gl_Color.rgb, 1.0);
}
)";
// The same for triangles whose corners all lie on the floor inside the walls (most of them): the
// test of the texture coordinates cost 4 % of the frame.
const char* const kFloorShaderInside = R"(
void main() {
  gl_FragColor = vec4(mix(carpet, line, line_cover(distance_to_line(floor_uv_at(gl_TexCoord[0].st)))) * gl_Color.rgb, 1.0);
}
)";
// The same field as flat class ids (a pixel is line where its centre is).
const char* const kFloorLabelShader = R"(
void main() {
  vec2 uv = floor_uv_at(gl_TexCoord[0].st);
  gl_FragColor = vec4(on_floor(uv) ? (distance_to_line(uv) <= half_width ? line : carpet) : outside, 1.0);
}
)";

// A one-channel table as a texture on the active unit, bilinear and clamped at its edges.
unsigned upload_table(const GlApi& gl, const std::string& backend, const char* what, GLint internal, int w, int h, GLenum type, const void* data) {
  unsigned tex = 0;
  gl.GenTextures(1, &tex);
  gl.BindTexture(GL_TEXTURE_2D, tex);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.TexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, GL_RED, type, data);
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + backend + "\": " + what + " texture upload failed");
  return tex;
}

}  // namespace

FloorMesh::FloorMesh(GlContext& ctx, const Field& field, const CameraConfig& cfg, const MirrorProfile& mirror, int ss)
    : ctx_(ctx), hx_(field.half_floor_x()), hy_(field.half_floor_y()), wall_height_(field.wall_height) {
  upload_distance_field(field);
  compile_programs(0.5 * field.line_width);
  build_mesh(cfg, mirror, ss);
  upload_mirror(mirror, ss);
}

FloorMesh::~FloorMesh() {
  ctx_.make_current();
  ctx_.gl().DeleteTextures(1, &tex_distance_);
  ctx_.gl().DeleteTextures(1, &tex_elevation_);
  ctx_.gl().DeleteProgram(prog_floor_);
  ctx_.gl().DeleteProgram(prog_floor_inside_);
  ctx_.gl().DeleteProgram(prog_floor_labels_);
}

// 2 cm texels over the floor inside the walls, texel centres at uv = (i + 0.5) / size.
void FloorMesh::upload_distance_field(const Field& field) {
  const GlApi& gl = ctx_.gl();
  const int tw = static_cast<int>(std::ceil(2 * hx_ / kDistanceTexel)), th = static_cast<int>(std::ceil(2 * hy_ / kDistanceTexel));
  std::vector<std::uint16_t> dist(static_cast<std::size_t>(tw) * th);
  for (int j = 0; j < th; ++j)
    for (int i = 0; i < tw; ++i) {
      const Eigen::Vector2d p(-hx_ + (i + 0.5) * 2 * hx_ / tw, -hy_ + (j + 0.5) * 2 * hy_ / th);
      const double d = std::min(field.distance_to_marking(p), kDistanceRange);
      dist[static_cast<std::size_t>(j) * tw + i] = static_cast<std::uint16_t>(std::lround(65535.0 * d / kDistanceRange));
    }
  tex_distance_ = upload_table(gl, ctx_.backend(), "floor distance", GL_R16, tw, th, GL_UNSIGNED_SHORT, dist.data());
}

void FloorMesh::upload_mirror(const MirrorProfile& mirror, int ss) {
  const GlApi& gl = ctx_.gl();
  constexpr double kStepPx = 1.0 / 16;
  const double lo = mirror.body_radius(), hi = mirror.rim();
  const int n = static_cast<int>(std::ceil((hi - lo) / kStepPx)) + 1;
  std::vector<float> elev(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) elev[static_cast<std::size_t>(i)] = static_cast<float>(mirror.elevation(std::min(hi, lo + i * kStepPx)));
  gl.ActiveTexture(GL_TEXTURE1);
  tex_elevation_ = upload_table(gl, ctx_.backend(), "mirror elevation", GL_R32F, n, 1, GL_FLOAT, elev.data());
  gl.ActiveTexture(GL_TEXTURE0);
  for (unsigned prog : {prog_floor_, prog_floor_inside_, prog_floor_labels_}) {
    gl.UseProgram(prog);
    gl.Uniform1i(gl.GetUniformLocation(prog, "elevation_map"), 1);
    gl.Uniform1f(gl.GetUniformLocation(prog, "elev_lo"), static_cast<float>(lo));
    gl.Uniform1f(gl.GetUniformLocation(prog, "elev_step"), static_cast<float>(kStepPx));
    gl.Uniform1f(gl.GetUniformLocation(prog, "elev_n"), static_cast<float>(n));
    gl.Uniform1f(gl.GetUniformLocation(prog, "body_px"), static_cast<float>(lo));
    gl.Uniform1f(gl.GetUniformLocation(prog, "rim_px"), static_cast<float>(hi));
    gl.Uniform1f(gl.GetUniformLocation(prog, "inv_ss"), static_cast<float>(1.0 / ss));
    gl.Uniform2f(gl.GetUniformLocation(prog, "floor_half"), static_cast<float>(hx_), static_cast<float>(hy_));
    gl.UseProgram(0);
  }
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + ctx_.backend() + "\": floor shader set-up failed");
}

void FloorMesh::set_frame_uniforms(const GlApi& gl, unsigned prog, const FrameProjection& f) const {
  gl.UseProgram(prog);
  gl.Uniform2f(gl.GetUniformLocation(prog, "centre_rs"), static_cast<float>(f.centre.x() * f.ss), static_cast<float>(f.centre.y() * f.ss));
  gl.Uniform1f(gl.GetUniformLocation(prog, "eye_height"), static_cast<float>(f.h));
  gl.Uniform4f(gl.GetUniformLocation(prog, "robot"), static_cast<float>(f.pose.x), static_cast<float>(f.pose.y), static_cast<float>(f.c),
               static_cast<float>(f.s));
  const char* rows[3] = {"cam_r0", "cam_r1", "cam_r2"};
  for (int i = 0; i < 3; ++i)
    gl.Uniform3f(gl.GetUniformLocation(prog, rows[i]), static_cast<float>(f.R(i, 0)), static_cast<float>(f.R(i, 1)), static_cast<float>(f.R(i, 2)));
}

void FloorMesh::compile_programs(double half_w) {
  const GlApi& gl = ctx_.gl();
  auto floor_program = [&](const char* body, const std::string& what, const Eigen::Vector3f& line, const Eigen::Vector3f& carpet,
                           const Eigen::Vector3f& outside) {
    const unsigned prog = ctx_.fragment_program((std::string(kFloorCommon) + body).c_str(), what);
    gl.UseProgram(prog);
    gl.Uniform1i(gl.GetUniformLocation(prog, "distance_map"), 0);
    gl.Uniform1f(gl.GetUniformLocation(prog, "range"), static_cast<float>(kDistanceRange));
    gl.Uniform1f(gl.GetUniformLocation(prog, "half_width"), static_cast<float>(half_w));
    gl.Uniform3f(gl.GetUniformLocation(prog, "line"), line[0], line[1], line[2]);
    gl.Uniform3f(gl.GetUniformLocation(prog, "carpet"), carpet[0], carpet[1], carpet[2]);
    gl.Uniform3f(gl.GetUniformLocation(prog, "outside"), outside[0], outside[1], outside[2]);
    gl.UseProgram(0);
    if (gl.GetError() != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + ctx_.backend() + "\": " + what + " shader set-up failed");
    return prog;
  };
  prog_floor_ = floor_program(kFloorShader, "floor", kLineWhite, kCarpet, kHallFloor);
  prog_floor_inside_ = floor_program(kFloorShaderInside, "floor (inside the walls)", kLineWhite, kCarpet, kHallFloor);
  auto label = [](LabelClass l) { return Eigen::Vector3f::Constant(static_cast<float>(l) / 255.0f); };
  prog_floor_labels_ = floor_program(kFloorLabelShader, "floor label", label(kLabelLine), label(kLabelField), label(kLabelFloorOutside));
}

// Texture coordinates are interpolated linearly across each cell, so rings are placed where the
// floor distance stops being linear in the image radius: a new ring whenever the midpoint of the
// floor distance deviates by more than `tol` from the chord (the mirror's isometric part needs few
// rings, the inner and outer parts many), and each ring has the fewest sectors whose chord strays at
// most `tol` from the arc on the floor (few near the robot, 128 at 8 m). llvmpipe's cost per
// triangle is a large share of the frame: the default mesh has about 2900 triangles where a fixed
// 120 sectors made 6720 (docs/camera.md).
void FloorMesh::build_mesh(const CameraConfig& cfg, const MirrorProfile& mirror, int ss) {
  const double tol = cfg.quality == "low" ? 0.01 : 0.003;
  auto floor_dist = [&](double r) {
    const double e = mirror.elevation(std::clamp(r, mirror.body_radius(), mirror.rim()));
    return e < -1e-3 ? cfg.mount_height / std::tan(-e) : 1e3;
  };
  std::vector<double> radii;
  double r0 = mirror.body_radius() - 1.0;
  radii.push_back(r0);
  while (r0 < mirror.rim() + 1.0) {
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
    r0 = std::min(r0 + step, mirror.rim() + 1.0);
    radii.push_back(r0);
    if (r0 >= mirror.rim() + 1.0) break;
  }
  const Eigen::Vector2d c = cfg.mirror_centre_px();
  std::vector<unsigned> ring_start;
  std::vector<int> ring_sectors;
  int sectors = 16;
  for (double r : radii) {
    const double R = std::min(floor_dist(r), 30.0);  // beyond: the hall's far floor, one colour
    while (sectors < 128 && R * (1.0 - std::cos(kPi / sectors)) > tol) sectors *= 2;
    ring_start.push_back(static_cast<unsigned>(mesh_dir_.size()));
    ring_sectors.push_back(sectors);
    const double e = mirror.elevation(std::clamp(r, mirror.body_radius(), mirror.rim()));
    for (int k = 0; k <= sectors; ++k) {
      const double b = kTwoPi * k / sectors;
      mesh_xy_.push_back(static_cast<float>((c.x() - r * std::sin(b)) * ss));
      mesh_xy_.push_back(static_cast<float>((c.y() - r * std::cos(b)) * ss));
      mesh_dir_.emplace_back(std::cos(e) * std::cos(b), std::cos(e) * std::sin(b), std::sin(e));
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
        mesh_idx_.insert(mesh_idx_.end(), {a, a + 1, b});
        ++ka;
      } else {
        mesh_idx_.insert(mesh_idx_.end(), {a, b + 1, b});
        ++kb;
      }
    }
  }
}

Eigen::Vector3f FloorMesh::far_floor(const WorldState& world, const Pose2& pose, bool labels) const {
  return labels ? Eigen::Vector3f::Constant(static_cast<float>(kLabelFloorOutside) / 255.0f)
                : Eigen::Vector3f(kHallFloor * (world.lighting.artificial_at(pose.translation()) / kRadianceScale));
}

// Each vertex gets a bit per hall wall that hides its floor point (bits 0-3: beyond x = hx, x = -hx,
// y = hy, y = -hy and below the line of sight over that wall) and all of them when its ray misses
// the floor.
void FloorMesh::place_vertices(const FrameProjection& f, const WorldState& world, bool labels) {
  const Pose2& pose = f.pose;
  const double c = f.c, s = f.s;
  const std::size_t nv = mesh_dir_.size();
  pos_.resize(nv * 3);
  col_.resize(nv * 4);
  tex_.resize(nv * 2);
  hidden_.resize(nv);
  const double keep = wall_height_ > 0 ? 1.0 - std::min(1.0, wall_height_ / f.h) : 2.0;  // hidden beyond a wall at t > keep
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3d d = f.R * mesh_dir_[i];
    Eigen::Vector2d w;
    std::uint8_t hidden = 0;
    if (d.z() < -1e-6) {
      const double t = f.h / -d.z();
      const double rx = t * d.x(), ry = t * d.y();
      w = {pose.x + c * rx - s * ry, pose.y + s * rx + c * ry};
      // The wall plane at fraction t_w of the way to the floor point hides it when t_w > keep.
      auto behind = [&](double wall, double p, double fp) { return std::fabs(wall - p) > keep * std::fabs(fp - p); };
      if (w.x() > hx_ && behind(hx_, pose.x, w.x())) hidden |= 1;
      if (w.x() < -hx_ && behind(-hx_, pose.x, w.x())) hidden |= 2;
      if (w.y() > hy_ && behind(hy_, pose.y, w.y())) hidden |= 4;
      if (w.y() < -hy_ && behind(-hy_, pose.y, w.y())) hidden |= 8;
    } else {
      w = {pose.x + 1e4 * (c * d.x() - s * d.y()), pose.y + 1e4 * (s * d.x() + c * d.y())};  // no floor: far beyond the walls
      hidden = 15;
    }
    if (std::fabs(w.x()) > hx_ || std::fabs(w.y()) > hy_) hidden |= 16;  // not on the floor inside the walls
    hidden_[i] = hidden;
    pos_[3 * i] = mesh_xy_[2 * i];
    pos_[3 * i + 1] = mesh_xy_[2 * i + 1];
    pos_[3 * i + 2] = -999.0f;
    tex_[2 * i] = mesh_xy_[2 * i];  // the shaders find the floor point of each pixel from its position
    tex_[2 * i + 1] = mesh_xy_[2 * i + 1];
    // The lamps' light only: sun beams are drawn over this, with sharp edges.
    const float illum = labels ? 1.0f : static_cast<float>(std::min(1.0, world.lighting.artificial_at(w) / kRadianceScale));
    col_[4 * i] = col_[4 * i + 1] = col_[4 * i + 2] = illum;
    col_[4 * i + 3] = 1.0f;
  }
}

// Drawn after everything standing on the floor and depth-tested at the far plane (written by
// nothing), so llvmpipe skips the floor shader where walls and robots cover it. A triangle whose
// vertices share a wall bit is not drawn, as the wall is drawn over it or nothing of the floor is
// there (the rasteriser's fill is the renderer's largest cost).
void FloorMesh::draw(const GlApi& gl, const FrameProjection& f, const WorldState& world, bool labels) {
  place_vertices(f, world, labels);
  idx_.clear();
  idx_inside_.clear();
  for (std::size_t t = 0; t < mesh_idx_.size(); t += 3) {
    const unsigned a = mesh_idx_[t], b = mesh_idx_[t + 1], cc = mesh_idx_[t + 2];
    if ((hidden_[a] & hidden_[b] & hidden_[cc] & 15) != 0) continue;
    auto& list = labels || ((hidden_[a] | hidden_[b] | hidden_[cc]) & 16) ? idx_ : idx_inside_;
    list.insert(list.end(), {a, b, cc});
  }
  gl.Enable(GL_DEPTH_TEST);  // behind walls and robots drawn before: not shaded
  gl.DepthMask(GL_FALSE);
  gl.DepthFunc(GL_LESS);
  gl.BindTexture(GL_TEXTURE_2D, tex_distance_);
  gl.ActiveTexture(GL_TEXTURE1);
  gl.BindTexture(GL_TEXTURE_2D, tex_elevation_);
  gl.ActiveTexture(GL_TEXTURE0);
  if (!idx_inside_.empty()) set_frame_uniforms(gl, prog_floor_inside_, f);
  set_frame_uniforms(gl, labels ? prog_floor_labels_ : prog_floor_, f);
  gl.EnableClientState(GL_TEXTURE_COORD_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, pos_.data());
  gl.ColorPointer(4, GL_FLOAT, 0, col_.data());
  gl.TexCoordPointer(2, GL_FLOAT, 0, tex_.data());
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(idx_.size()), GL_UNSIGNED_INT, idx_.data());
  if (!idx_inside_.empty()) {
    gl.UseProgram(prog_floor_inside_);
    gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(idx_inside_.size()), GL_UNSIGNED_INT, idx_inside_.data());
  }
  gl.DisableClientState(GL_TEXTURE_COORD_ARRAY);
  gl.UseProgram(0);
}

// In cells of at most 0.1 m projected through the mirror, so a beam's edges are as sharp as the
// pixels (a per-vertex light on the image-fixed floor mesh would smear them over a mesh cell).
void FloorMesh::draw_sun_beams(const GlApi& gl, const FrameProjection& f, const WorldState& world) {
  set_frame_uniforms(gl, prog_floor_, f);
  gl.EnableClientState(GL_TEXTURE_COORD_ARRAY);
  for (const auto& sp : world.lighting.sun) {
    if (sp.surface != SunPatch::Surface::kFloor) continue;
    const double x0 = std::max(-hx_, sp.centre.x() - sp.half_size.x()), x1 = std::min(hx_, sp.centre.x() + sp.half_size.x());
    const double y0 = std::max(-hy_, sp.centre.y() - sp.half_size.y()), y1 = std::min(hy_, sp.centre.y() + sp.half_size.y());
    if (x1 <= x0 || y1 <= y0) continue;
    const int nx = std::max(1, static_cast<int>(std::ceil((x1 - x0) / 0.1))), ny = std::max(1, static_cast<int>(std::ceil((y1 - y0) / 0.1)));
    pos_.clear();
    col_.clear();
    tex_.clear();
    auto vertex = [&](int i, int j) {
      const Eigen::Vector2d w(x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny);
      float xyz[3];
      f(Eigen::Vector3d(w.x(), w.y(), 0.0), xyz);
      pos_.insert(pos_.end(), {xyz[0], xyz[1], -999.0f});
      tex_.insert(tex_.end(), {xyz[0], xyz[1]});
      const float il = static_cast<float>(std::min(1.0, world.lighting.at(w) / kRadianceScale));
      col_.insert(col_.end(), {il, il, il, 1.0f});
    };
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        for (const auto& [a, b] : std::array<std::pair<int, int>, 6>{{{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j}, {i + 1, j + 1}, {i, j + 1}}})
          vertex(a, b);
    gl.VertexPointer(3, GL_FLOAT, 0, pos_.data());
    gl.ColorPointer(4, GL_FLOAT, 0, col_.data());
    gl.TexCoordPointer(2, GL_FLOAT, 0, tex_.data());
    gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(pos_.size() / 3));
  }
  gl.DisableClientState(GL_TEXTURE_COORD_ARRAY);
  gl.UseProgram(0);
}

}  // namespace omniloc::sim
