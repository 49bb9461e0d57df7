// The host side of olp/1 (docs/protocol.md): framing, the strict readers of ready and estimate,
// and every failure class of section 7 against a real client process that misbehaves on purpose
// (tests/protocol_clients/faulty_client.py). Each failure must throw a RuntimeFailure naming the
// robot, the frame and the reason, and leave no process of the client's group behind.
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>

#include "core/error.hpp"
#include "external/external_localizer.hpp"
#include "external/olp_framing.hpp"
#include "external/sha256.hpp"
#include "core/install_paths.hpp"

namespace omniloc::external {
namespace {

namespace fs = std::filesystem;

std::string python() { return fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3"; }
const std::string kFaulty = std::string(omniloc::source_dir().string()) + "/tests/protocol_clients/faulty_client.py";

// ---- framing --------------------------------------------------------------------------------------

TEST(OlpFraming, RoundTripWithBinaryPartsByteByByte) {
  const std::string image = std::string("\n{\"x\"}\0\xff", 8) + std::string(100, 'a');
  const std::string bytes = encode_message(Json{{"type", "frame"}, {"k", 3}}, {{"image", "uint8", {2, 6, 9}, image}}) +
                            encode_message(Json{{"type", "end"}});
  MessageReader r;
  std::vector<Message> got;
  for (char c : bytes) {  // the worst pipe: one byte per read
    r.feed(std::string_view(&c, 1));
    while (auto m = r.next()) got.push_back(std::move(*m));
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].type(), "frame");
  EXPECT_EQ(got[0].header["k"], 3);
  ASSERT_EQ(got[0].parts.size(), 1u);
  EXPECT_EQ(got[0].parts[0], image);
  EXPECT_EQ(got[0].header["binary"][0]["bytes"], 108);
  EXPECT_EQ(got[0].header["binary"][0]["shape"], Json::array({2, 6, 9}));
  EXPECT_EQ(got[1].type(), "end");
  EXPECT_EQ(r.pending(), 0u);
}

TEST(OlpFraming, DoublesReadBackExactly) {
  const double v[] = {0.1, 1.0 / 3.0, -2.718281828459045, 1e-300, 6.02214076e23};
  const std::string line = encode_message(Json{{"type", "x"}, {"v", v}});
  MessageReader r;
  r.feed(line);
  const auto m = r.next();
  ASSERT_TRUE(m);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(m->header["v"][i].get<double>(), v[i]);
}

TEST(OlpFraming, ToleratesCrLf) {
  MessageReader r;
  r.feed("{\"type\": \"ready\"}\r\n");
  const auto m = r.next();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->type(), "ready");
}

TEST(OlpFraming, RejectsWhatIsNotAJsonObjectLine) {
  for (const std::string bad : {"hello world\n", "[1, 2]\n", "{\"a\": 1, \"a\": 2}\n", "{\"a\": NaN}\n", "{\"a\": 1e999}\n",
                                "{\"s\": \"\xc3\x28\"}\n", "\n"}) {
    MessageReader r;
    r.feed(bad);
    EXPECT_THROW(r.next(), ProtocolError) << bad;
  }
}

TEST(OlpFraming, RejectsMalformedBinaryAnnouncements) {
  for (const std::string bad : {R"({"binary": {}})", R"({"binary": [{"name": "i", "dtype": "float32", "shape": [1], "bytes": 4}]})",
                                R"({"binary": [{"name": "i", "dtype": "uint8", "shape": [2, 3], "bytes": 5}]})",
                                R"({"binary": [{"name": "i", "dtype": "uint8", "shape": [-1], "bytes": 1}]})",
                                R"({"binary": [{"name": "i", "dtype": "uint8", "shape": [100000, 100000], "bytes": 10000000000}]})"}) {
    MessageReader r;
    r.feed(bad + "\n");
    EXPECT_THROW(r.next(), ProtocolError) << bad;
  }
}

TEST(OlpFraming, RejectsAnEndlessLine) {
  MessageReader r;
  r.feed(std::string(kMaxLineBytes + 1, 'x'));
  EXPECT_THROW(r.next(), ProtocolError);
}

TEST(OlpFraming, WaitsForEveryByteOfTheParts) {
  MessageReader r;
  r.feed(std::string(R"({"type": "f", "binary": [{"name": "a", "dtype": "uint8", "shape": [3], "bytes": 3}]})") + "\nab");
  EXPECT_FALSE(r.next());
  r.feed("c");
  const auto m = r.next();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->parts[0], "abc");
}

// ---- the strict readers -----------------------------------------------------------------------------

TEST(OlpMessages, ReadyIsReadStrictly) {
  const std::vector<std::string> reserved{"mcl", "matching"};
  const auto ok = ExternalLocalizer::parse_ready(Json{{"type", "ready"}, {"name", "my_pf-2.0"}, {"version", "1"}, {"wants_image", true}}, reserved);
  EXPECT_EQ(ok.name, "my_pf-2.0");
  EXPECT_TRUE(ok.wants_image);
  EXPECT_FALSE(ok.needs_start_pose);
  auto err = [&](const Json& j) {
    try {
      ExternalLocalizer::parse_ready(j, reserved);
    } catch (const ProtocolError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(err(Json{{"version", "1"}}).find("/name"), std::string::npos);
  EXPECT_NE(err(Json{{"name", "a b"}, {"version", "1"}}).find("/name"), std::string::npos);
  EXPECT_NE(err(Json{{"name", "mcl"}, {"version", "1"}}).find("built-in"), std::string::npos);
  EXPECT_NE(err(Json{{"name", "x"}}).find("/version"), std::string::npos);
  EXPECT_NE(err(Json{{"name", "x"}, {"version", "1"}, {"needs_start_pose", 1}}).find("/needs_start_pose"), std::string::npos);
  EXPECT_NE(err(Json{{"name", "x"}, {"version", "1"}, {"protocol", "olp/2"}}).find("/protocol"), std::string::npos);
}

TEST(OlpMessages, EstimateIsReadStrictly) {
  const Json good{{"type", "estimate"}, {"k", 7}, {"pose", {1.0, -2.0, 7.0}}, {"valid", true},
                  {"covariance", {1, 0, 0, 0, 2, 0, 0, 0, 3}}, {"mode", "tracking"}, {"extra", {{"particles", 300}}}};
  const Estimate e = ExternalLocalizer::parse_estimate(good, 7);
  EXPECT_DOUBLE_EQ(e.pose.x, 1.0);
  EXPECT_NEAR(e.pose.theta, 7.0 - 2 * M_PI, 1e-12);  // wrapped
  EXPECT_TRUE(e.valid);
  EXPECT_EQ(e.covariance(1, 1), 2.0);
  EXPECT_EQ(e.mode, LocalizerMode::kTracking);
  EXPECT_EQ(e.mode_label, "tracking");
  EXPECT_EQ(e.extra.at("particles"), 300.0);
  auto err = [&](Json j, long long k = 7) {
    try {
      ExternalLocalizer::parse_estimate(j, k);
    } catch (const ProtocolError& ex) {
      return std::string(ex.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(err(good, 8).find("estimate for frame 7, expected 8"), std::string::npos);
  Json j = good;
  j["pose"] = {1.0, 2.0};
  EXPECT_NE(err(j).find("/pose"), std::string::npos);
  j = good;
  j["pose"][1] = "1";
  EXPECT_NE(err(j).find("/pose/1"), std::string::npos);
  j = good;
  j["pose"][2] = std::nan("");  // a client library could hand us one through a non-JSON path
  EXPECT_NE(err(j).find("/pose/2: expected a finite number"), std::string::npos);
  j = good;
  j.erase("valid");
  EXPECT_NE(err(j).find("/valid"), std::string::npos);
  j = good;
  j["covariance"] = {1, 2, 3};
  EXPECT_NE(err(j).find("/covariance"), std::string::npos);
  j = good;
  j["mode"] = "Tracking!";
  EXPECT_NE(err(j).find("/mode"), std::string::npos);
  j = good;
  j["extra"] = {{"t", 1}};
  EXPECT_NE(err(j).find("frames.csv"), std::string::npos);
  j = good;
  j["extra"] = {{"a", "b"}};
  EXPECT_NE(err(j).find("/extra/a"), std::string::npos);
}

TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

// ---- a real client process that misbehaves ------------------------------------------------------------

struct Harness {
  fs::path dir;
  std::string pid_file;
  Harness() {
    dir = fs::temp_directory_path() / ("olp_test_" + std::to_string(getpid()) + "_" + std::to_string(counter()++));
    fs::create_directories(dir);
    pid_file = (dir / "pids").string();
  }
  ~Harness() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  static int& counter() {
    static int c = 0;
    return c;
  }
  std::unique_ptr<ExternalLocalizer> start(const std::string& mode, double frame_timeout = 5, double hello_timeout = 10) {
    const Json j{{"command", {python(), kFaulty, mode, pid_file}}, {"frame_timeout_s", frame_timeout},
                 {"hello_timeout_s", hello_timeout}, {"exit_timeout_s", 1}};
    JsonReader r(j, "/localizer");  // the reader keeps a reference: j must outlive it
    ExternalConfig cfg = ExternalConfig::from_json(r);
    Session s;
    s.robot = 2;
    s.scenario = "test";
    s.log_dir = dir.string();
    s.seed = 42;
    s.reserved_names = {"mcl", "odometry_only"};
    return std::make_unique<ExternalLocalizer>(cfg, s);
  }
  std::vector<int> pids() const {
    std::ifstream f(pid_file);
    std::vector<int> v;
    for (int p; f >> p;) v.push_back(p);
    return v;
  }
  // True when none of the recorded processes is alive (zombies of other parents count as gone).
  // Every process of the client's group is gone (or a zombie). A SIGKILL sent to the group takes
  // effect when each process is next scheduled: on a busy machine that can be a moment after the
  // run reported the failure, so this waits up to 2 s for it (the kill itself is what is tested).
  bool all_gone() const {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    for (;;) {
      bool gone = true;
      for (int p : pids()) {
        std::ifstream st("/proc/" + std::to_string(p) + "/stat");
        std::string line;
        if (st && std::getline(st, line)) {
          const auto close = line.rfind(')');
          if (close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z') gone = false;
        }
      }
      if (gone || std::chrono::steady_clock::now() > deadline) return gone;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
};

Observations obs_at(double t) {
  Observations o;
  o.t = t;
  o.line_points = {{1.0, 0.5}, {2.0, -0.25}};
  return o;
}

Odometry step() {
  Odometry od;
  od.delta = Pose2(0.01, 0.002, 0.003);
  return od;
}

// Runs frames until the client fails; returns the failure message ("" when it never failed).
std::string run_until_failure(ExternalLocalizer& loc, int frames = 10) {
  try {
    loc.reset(Pose2(1.0, 2.0, 0.5));
    for (int k = 0; k < frames; ++k) loc.update(obs_at(k / 30.0), step(), std::nullopt);
    loc.finish();
  } catch (const RuntimeFailure& e) {
    return e.what();
  }
  return "";
}

TEST(ExternalClient, WellBehavedClientDeadReckonsLikeOdometryOnly) {
  Harness h;
  auto loc = h.start("ok");
  EXPECT_EQ(loc->name(), "faulty");
  EXPECT_TRUE(loc->wants_start_pose());
  Pose2 expect(1.0, 2.0, 0.5);
  loc->reset(expect);
  for (int k = 0; k < 20; ++k) {
    const Estimate e = loc->update(obs_at(k / 30.0), step(), 0.5);
    expect = expect.compose(step().delta);
    EXPECT_NEAR(e.pose.x, expect.x, 1e-12);
    EXPECT_NEAR(e.pose.y, expect.y, 1e-12);
    EXPECT_EQ(e.mode_label, "dead_reckoning");
    EXPECT_EQ(e.mode, LocalizerMode::kDeadReckoning);
  }
  loc->finish();
  EXPECT_TRUE(h.all_gone());
  EXPECT_TRUE(fs::exists(h.dir / "client_r2.stderr.log"));
  const Json p = loc->provenance();
  EXPECT_EQ(p["name"], "faulty");
  ASSERT_EQ(p["files"].size(), 2u);  // the interpreter and the script
  EXPECT_EQ(p["files"][1]["sha256"], sha256_file(kFaulty));
}

void expect_failure(const std::string& msg, const std::vector<std::string>& parts) {
  ASSERT_FALSE(msg.empty()) << "the client's fault went unnoticed";
  for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "missing \"" << p << "\" in:\n" << msg;
}

TEST(ExternalClient, NoReadyWithinTheHelloTimeout) {
  Harness h;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    h.start("no_ready", 5, 0.5);
    ADD_FAILURE() << "no failure";
  } catch (const RuntimeFailure& e) {
    expect_failure(e.what(), {"(robot 2)", "before ready", "no ready within 0.5 s", "faulty_client: mode no_ready"});
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  EXPECT_TRUE(h.all_gone());
}

TEST(ExternalClient, ExitBeforeEnd) {
  Harness h;
  auto loc = h.start("exit_at:3");
  expect_failure(run_until_failure(*loc), {"frame 3", "exited with status 3", "faulty_client: exit_at at frame 3"});
  EXPECT_TRUE(h.all_gone());
}

TEST(ExternalClient, KilledBySignal) {
  Harness h;
  auto loc = h.start("kill_at:2");
  expect_failure(run_until_failure(*loc), {"frame 2", "killed by signal 9"});
}

TEST(ExternalClient, StallEndsTheWholeProcessGroup) {
  Harness h;
  auto loc = h.start("stall_at:4", 0.5);
  const auto t0 = std::chrono::steady_clock::now();
  expect_failure(run_until_failure(*loc), {"frame 4", "no estimate for frame 4 within 0.5 s", "stall_at at frame 4"});
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  EXPECT_EQ(h.pids().size(), 2u);  // the client and its grandchild `sleep 1000`
  EXPECT_TRUE(h.all_gone());
}

TEST(ExternalClient, StallIgnoringSigtermIsKilled) {
  Harness h;
  auto loc = h.start("ignore_term_at:1", 0.3);
  expect_failure(run_until_failure(*loc), {"frame 1", "no estimate for frame 1"});
  EXPECT_TRUE(h.all_gone());
}

TEST(ExternalClient, ClientThatStopsReadingCannotBlockTheImageWrite) {
  Harness h;
  auto loc = h.start("no_read", 0.5);
  ASSERT_TRUE(loc->wants_image());
  auto img = std::make_shared<Image>();
  img->width = img->height = 640;
  img->rgb.assign(640 * 640 * 3, 7);
  try {
    loc->reset(Pose2());
    for (int k = 0; k < 10; ++k) {
      Observations o = obs_at(k / 30.0);
      o.image = img;
      loc->update(o, step(), std::nullopt);
    }
    ADD_FAILURE() << "no failure";
  } catch (const RuntimeFailure& e) {
    expect_failure(e.what(), {"did not read"});
  }
  EXPECT_TRUE(h.all_gone());
}

TEST(ExternalClient, NonJsonOnStdout) {
  Harness h;
  auto loc = h.start("garbage_at:1");
  expect_failure(run_until_failure(*loc), {"frame 1", "not a JSON object: hello world"});
}

TEST(ExternalClient, WrongFrameNumber) {
  Harness h;
  auto loc = h.start("wrong_k_at:5");
  expect_failure(run_until_failure(*loc), {"frame 5", "estimate for frame 6, expected 5"});
}

TEST(ExternalClient, NonFiniteNumber) {
  Harness h;
  auto loc = h.start("nan_at:2");  // Python's json writes NaN, which is not JSON
  expect_failure(run_until_failure(*loc), {"frame 2", "not a JSON object", "NaN and Infinity are not JSON numbers"});
}

TEST(ExternalClient, BuiltInNameRefused) {
  Harness h;
  try {
    h.start("bad_name");
    ADD_FAILURE() << "no failure";
  } catch (const RuntimeFailure& e) {
    expect_failure(e.what(), {"before ready", "\"mcl\" is a built-in localizer's name"});
  }
}

TEST(ExternalClient, NonZeroExitAfterEnd) {
  Harness h;
  auto loc = h.start("bad_exit");
  expect_failure(run_until_failure(*loc, 3), {"after end", "exited with status 4 after end"});
}

TEST(ExternalClient, NoExitAfterEnd) {
  Harness h;
  auto loc = h.start("linger");
  expect_failure(run_until_failure(*loc, 3), {"did not exit within 1 s of end"});
  EXPECT_TRUE(h.all_gone());
}

TEST(ExternalClient, ProgramThatCannotStart) {
  const fs::path f = fs::temp_directory_path() / ("olp_not_exec_" + std::to_string(getpid()));
  std::ofstream(f) << "#!/bin/sh\n";
  fs::permissions(f, fs::perms::owner_read | fs::perms::owner_write);
  const Json j1{{"command", {f.string()}}}, j2{{"command", {python(), "no_such_script.py"}}},
      j3{{"command", {"surely-no-such-program-olp"}}};
  JsonReader r(j1, "/localizer");
  try {
    ExternalConfig::from_json(r);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/localizer/command/0");
  }
  JsonReader r2(j2, "/localizer");
  try {
    ExternalConfig::from_json(r2);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/localizer/command/1");
  }
  JsonReader r3(j3, "/localizer");
  EXPECT_THROW(ExternalConfig::from_json(r3), ConfigError);
  fs::remove(f);
}

TEST(ExternalConfig, DefaultLabelIsTheScriptsStem) {
  EXPECT_EQ(default_label(Json{{"command", {"python3", "-u", "clients/python/examples/particle_filter.py", "--x"}}}), "particle_filter");
  EXPECT_EQ(default_label(Json{{"command", {"./build/olp_cpp_example"}}}), "olp_cpp_example");
  EXPECT_EQ(default_label(Json{{"command", {"python3", "-m", "mypkg.loc"}}}), "python3");
}

}  // namespace
}  // namespace omniloc::external
