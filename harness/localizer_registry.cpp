#include "harness/localizer_registry.hpp"

#include "localization/grid_global.hpp"
#include "localization/hybrid.hpp"
#include "localization/landmarks/landmark_localizer.hpp"
#include "localization/matching.hpp"
#include "localization/mcl.hpp"
#include "localization/modern/ukf_mh.hpp"
#include "localization/odometry_only.hpp"

namespace omniloc::harness {

namespace {
// An external localizer's keys. Its "label" is the name its results carry, so it may not be a
// built-in localizer's: tables pair rows by that name and would take the client for the built-in.
external::ExternalConfig read_external(JsonReader& r) {
  external::ExternalConfig cfg = external::ExternalConfig::from_json(r);
  for (const auto& l : localizers())
    if (!cfg.label.empty() && cfg.label == l.type)
      throw ConfigError(r.child_path("label"), "\"" + cfg.label + "\"", "a name that is not a built-in localizer's (omniloc list)");
  return cfg;
}
// What the scenario's camera declares, as ukf_mh's defaults take it.
modern::DeclaredCamera declared_camera(const LocalizerContext& ctx) { return {ctx.camera_latency, ctx.camera_mount_height, ctx.camera_vibration}; }

// A built-in's entry from one reader of its parameters: `make` builds from what `read` returns and
// `check` is `read` alone, so validation and building can never accept different files or say
// different errors.
template <class Read, class Build>
LocalizerInfo builtin(std::string type, std::string description, bool needs_start_pose, bool needs_vision, Read read, Build build,
                      std::function<Json()> schema) {
  return {std::move(type), std::move(description), needs_start_pose, needs_vision,
          [read, build](JsonReader& r, const LocalizerContext& ctx) -> std::unique_ptr<Localizer> { return build(read(r, ctx), ctx); },
          std::move(schema), [read](JsonReader& r, const LocalizerContext& ctx) { (void)read(r, ctx); }};
}

// The reader of a parameter struct that needs nothing from the context.
template <class P>
auto reads() {
  return [](JsonReader& r, const LocalizerContext&) { return P::from_json(r); };
}
}  // namespace

const std::vector<LocalizerInfo>& localizers() {
  static const std::vector<LocalizerInfo> list = {
      builtin("odometry_only", "dead reckoning from the true start pose (odometry drift baseline)", true, false,
              [](JsonReader&, const LocalizerContext&) { return 0; },
              [](int, const LocalizerContext&) { return std::make_unique<OdometryOnlyLocalizer>(); }, [] { return Json::object(); }),
      builtin("matching", "matching-optimisation tracking (RPROP on the distance map) fused with odometry by a Kalman filter (paper 002)", true, true,
              reads<MatchingParams>(),
              [](MatchingParams p, const LocalizerContext& ctx) { return std::make_unique<MatchingLocalizer>(*ctx.field, p, ctx.cache_dir); },
              &MatchingParams::schema),
      builtin("mcl", "Monte Carlo localization, distance-map sensor model: 600 particles with compass headings (paper 002); without a compass 5000, KLD-adaptive, 2 m clamp", false, true,
              reads<McLParams>(),
              [](McLParams p, const LocalizerContext& ctx) { return std::make_unique<McLLocalizer>(*ctx.field, p, ctx.seed, ctx.cache_dir); },
              &McLParams::schema),
      builtin("hybrid", "MCL until converged, then matching tracking; wrong-localisation detection restarts MCL (paper 002)", false, true,
              reads<HybridParams>(),
              [](HybridParams p, const LocalizerContext& ctx) { return std::make_unique<HybridLocalizer>(*ctx.field, p, ctx.seed, ctx.cache_dir); },
              &HybridParams::schema),
      builtin("grid_global", "MTi-heading grid search (315 samples, best 5 refined by RPROP, up to 3 shifted passes), then matching tracking with MTi drift correction (paper 000)", false, true,
              reads<GridGlobalParams>(),
              [](GridGlobalParams p, const LocalizerContext& ctx) { return std::make_unique<GridGlobalLocalizer>(*ctx.field, p, ctx.cache_dir); },
              &GridGlobalParams::schema),
      builtin("ukf_mh", "modern reference: a few unscented Kalman filter hypotheses on line points associated with the markings, validity-filtered, with Falcons-style simplex field fits as alternative poses (after B-Human's SelfLocator / UKFPose2D and the Falcons' localization; docs/modern_localizer.md)", false, true,
              [](JsonReader& r, const LocalizerContext& ctx) { return modern::UkfMhParams::from_json(r, declared_camera(ctx)); },
              [](modern::UkfMhParams p, const LocalizerContext& ctx) { return std::make_unique<modern::UkfMhLocalizer>(*ctx.field, p, ctx.seed, ctx.cache_dir); },
              &modern::UkfMhParams::schema),
      builtin("landmarks", "pose from bearings of coloured blobs (goal edges, colour cubes) matched by colour; least squares with >= 4, ToTal-like with 3 (papers 004 and 003)", false, true,
              reads<LandmarkLocalizerParams>(),
              [](LandmarkLocalizerParams p, const LocalizerContext& ctx) { return std::make_unique<LandmarkLocalizer>(*ctx.field, p); },
              [] { return params_schema(LandmarkLocalizerParams::params()); }),
      // Not a builtin(): its check reads the keys and checks the program, while building needs a run
      // (the session its client is told of) and starts the program.
      {"external", "a user's localizer in any language, run as its own process and spoken to in olp/1 (docs/protocol.md); named in results by its label, else by the name the client reports", false, true,
       [](JsonReader& r, const LocalizerContext& ctx) -> std::unique_ptr<Localizer> {
         external::ExternalConfig cfg = read_external(r);
         if (!ctx.session)
           throw ConfigError(r.child_path("type"), "\"external\"", "a localizer that can run here (an external localizer runs only in a scenario run)");
         return std::make_unique<external::ExternalLocalizer>(std::move(cfg), *ctx.session);
       },
       &external::ExternalConfig::schema,
       [](JsonReader& r, const LocalizerContext&) { read_external(r); }},
  };
  return list;
}

const LocalizerInfo& localizer_info(const std::string& type, const std::string& path) {
  std::string known;
  for (const auto& l : localizers()) {
    if (l.type == type) return l;
    known += (known.empty() ? "\"" : ", \"") + l.type + "\"";
  }
  throw ConfigError(path, "\"" + type + "\"", "a localizer type: one of " + known);
}

const LocalizerInfo& localizer_info(const LocalizerSpec& l) {
  try {
    return localizer_info(l.type(), json_child(l.path, "type"));
  } catch (const ConfigError& e) {
    throw LocalizerError(e);
  }
}

std::unique_ptr<Localizer> make_localizer(const Json& j, const std::string& path, const LocalizerContext& ctx,
                                          Json* effective) {
  JsonReader r(j, path, effective);
  r.allow("comment");
  const std::string type = r.string("type", std::nullopt);
  const LocalizerInfo& info = localizer_info(type, r.child_path("type"));
  auto loc = info.make(r, ctx);
  r.finish();
  return loc;
}

std::unique_ptr<Localizer> make_localizer(const LocalizerSpec& l, const LocalizerContext& ctx, Json* effective) {
  try {
    return make_localizer(l.json, l.path, ctx, effective);
  } catch (const ConfigError& e) {
    throw LocalizerError(e);
  }
}

void check_localizer(const LocalizerSpec& l, const LocalizerContext& ctx) {
  try {
    Json effective;
    JsonReader r(l.json, l.path, &effective);
    r.allow("comment");
    const std::string type = r.string("type", std::nullopt);
    const LocalizerInfo& info = localizer_info(type, r.child_path("type"));
    if (info.check) info.check(r, ctx);
    else info.make(r, ctx);
    r.finish();
  } catch (const ConfigError& e) {
    throw LocalizerError(e);
  }
}

}  // namespace omniloc::harness
