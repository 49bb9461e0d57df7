// The camera assembled from its parts: the floor mesh (floor_mesh.hpp), the standing scene
// (scene_mesh.hpp) and the sensor (photometry.hpp) share one GL context and one frame projection
// (frame_projection.hpp); this file orders their draws, the motion blur's sub-frames and the truth
// projections. Units: metres, radians; frames: world, robot, image (see panoramic_camera.hpp).
#include "sim/render/panoramic_camera.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "sim/render/floor_mesh.hpp"
#include "sim/render/frame_projection.hpp"
#include "sim/render/photometry.hpp"
#include "sim/render/scene_mesh.hpp"

namespace omniloc::sim {

namespace {

// The framebuffer is bound before the floor mesh uploads its texture and compiles its shaders.
std::unique_ptr<GlContext> bound_context(const std::string& backend, int width, int height) {
  std::unique_ptr<GlContext> ctx = make_gl_context(backend);
  ctx->bind_framebuffer(width, height);
  return ctx;
}

}  // namespace

struct PanoramicCameraImpl {
  PanoramicCameraImpl(const CameraConfig& cfg, const MirrorProfile& mirror, const Field& field)
      : ss(cfg.quality == "high" ? 2 : 1),
        W(cfg.width * ss),
        H(cfg.height * ss),
        ctx(bound_context(cfg.backend, W, H)),
        floor(*ctx, field, cfg, mirror, ss),
        scene(field),
        photometry(cfg, mirror, ss) {}

  int ss;                    // supersampling factor
  int W, H;                  // render size (W * ss ...)
  std::unique_ptr<GlContext> ctx;  // before the parts holding GL objects: destroyed after them
  FloorMesh floor;
  SceneMesh scene;
  Photometry photometry;
  std::vector<unsigned char> readback;  // labels, RGBA8
};

PanoramicCamera::PanoramicCamera(const CameraConfig& config, const Field& field)
    : cfg_(config), mirror_(MirrorProfile::preset(config.mirror, config.rim_px(), config.mount_height)) {
  impl_ = std::make_unique<PanoramicCameraImpl>(cfg_, mirror_, field);
}

PanoramicCamera::~PanoramicCamera() = default;

const std::string& PanoramicCamera::backend() const { return impl_->ctx->backend(); }
const GlDeviceInfo& PanoramicCamera::device() const { return impl_->ctx->device(); }

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

// One draw of the scene into the bound framebuffer. `labels`: flat class colours, no lighting.
void draw_scene(PanoramicCameraImpl& m, const CameraConfig& cfg, const MirrorProfile& mirror, const Eigen::Vector2d& centre,
                const WorldState& world, const RobotState& me, const Eigen::Matrix3d& R, bool labels) {
  const GlApi& gl = m.ctx->gl();
  gl.Viewport(0, 0, m.W, m.H);
  gl.MatrixMode(GL_PROJECTION);
  gl.LoadIdentity();
  gl.Ortho(0, m.W, m.H, 0, 0.0, 1000.0);  // render space: x right, y down; z = -depth
  gl.MatrixMode(GL_MODELVIEW);
  gl.LoadIdentity();
  gl.ShadeModel(GL_SMOOTH);
  // Above the walls: the hall, seen as its far floor under the light at the robot (the floor mesh
  // skips the rays that miss the floor).
  const Eigen::Vector3f bg = m.floor.far_floor(world, me.pose, labels);
  gl.ClearColor(bg[0], bg[1], bg[2], 1.0f);
  gl.DepthMask(GL_TRUE);  // the clear writes depth only through the mask (the floor leaves it off)
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.EnableClientState(GL_COLOR_ARRAY);

  const FrameProjection f(mirror, centre, m.ss, me.pose, cfg.mount_height, R);
  m.scene.draw_standing(gl, f, world, me, labels);
  // The floor after everything standing on it, so that the depth test spares the floor shader
  // wherever walls and robots cover it.
  m.floor.draw(gl, f, world, labels);
  if (!labels) m.floor.draw_sun_beams(gl, f, world);
  m.scene.draw_floor_patches(gl, f, world, labels);
  m.scene.draw_body(gl, f, world, labels);
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
  m.photometry.draw_noise_table(rng);  // first: the order of the draws from `rng` shapes every frame after
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
  const int subframes = m.photometry.subframes(me->velocity.norm(), exposure_s);
  // Does anything but this robot move in the image over the exposure (half a millimetre)?
  bool others_still = world.ball.velocity.norm() * exposure_s <= 5e-4;
  for (const auto& r : world.robots)
    if (r.id != robot_id && r.velocity.norm() * exposure_s > 5e-4) others_still = false;
  if (subframes == 1) {
    draw_scene(m, cfg_, mirror_, centre(), world, *me, R, false);
    m.ctx->read_rgba16(m.photometry.radiance());
  } else if (others_still) {
    // Only this robot moves: the scene once at mid-exposure, and the sub-frames (the same times as
    // below) resampled from it along each pixel's image motion (the re-renders were most of
    // a field_robot frame's cost: docs/camera.md "How the effects are computed").
    const double mid = 0.5 * exposure_s;
    WorldState w = world;
    for (auto& r : w.robots) r.pose = Pose2(r.pose.x - mid * r.velocity.x(), r.pose.y - mid * r.velocity.y(), r.pose.theta);
    w.ball.position -= mid * w.ball.velocity;
    draw_scene(m, cfg_, mirror_, centre(), w, *w.robot(robot_id), R, false);
    m.ctx->read_rgba16(m.photometry.radiance());
    m.ctx->read_depth(m.photometry.depth());
    std::vector<double> taus(static_cast<std::size_t>(subframes));
    for (int k = 0; k < subframes; ++k) taus[static_cast<std::size_t>(k)] = mid - exposure_s * (1.0 - (k + 0.5) / subframes);
    m.photometry.translation_blur(Pose2(0, 0, me->pose.theta).inverse_transform(me->velocity), taus);
  } else {
    m.photometry.clear_sum();
    for (int k = 0; k < subframes; ++k) {
      const double back = exposure_s * (1.0 - (k + 0.5) / subframes);  // seconds before t
      WorldState w = world;
      for (auto& r : w.robots) r.pose = Pose2(r.pose.x - back * r.velocity.x(), r.pose.y - back * r.velocity.y(), r.pose.theta);
      w.ball.position -= back * w.ball.velocity;
      draw_scene(m, cfg_, mirror_, centre(), w, *w.robot(robot_id), R, false);
      m.ctx->read_rgba16(m.photometry.subframe());
      m.photometry.add_subframe();
    }
    m.photometry.average(subframes);
  }
  // Over the exposure the robot turned by omega * T; the image at time t - s is the final one turned
  // back by omega * s about the mirror axis (robot forward up, left left: a left turn moves the
  // scene clockwise on the image).
  m.photometry.apply_optics(me->omega * exposure_s);
  return m.photometry.expose(st, off);
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
