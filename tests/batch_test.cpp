// `meshmorph batch` (docs/batch.md): manifest expansion and its errors, SHA-256, shards, the
// summary; the worker's shared retarget precomputation against `meshmorph retarget`'s bytes; and
// (natively) whole batches through the CLI binary: a broken and a crashing job, a batch killed
// midway and resumed, shards gathered, the Slurm scripts run by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#ifndef __EMSCRIPTEN__
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

#include "app/batch_manifest.h"
#include "app/batch_state.h"
#include "app/batch_worker.h"
#include "app/json_options.h"
#include "app/retarget_job.h"
#include "io/asset.h"
#include "merge/cut.h"
#include "metrics/transfer_metrics.h"
#include "mesh/topology.h"
#include "test_meshes.h"
#include "test_support.h"

namespace mm {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using app::BatchKind;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

[[maybe_unused]] void write_text(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// A fresh scratch folder of this process (ctest -j runs tests of this file side by side), removed
// when the process ends (unless a test failed).
std::string fresh_dir(const std::string& name) {
  struct Cleanup {
    std::vector<std::string> dirs;
    ~Cleanup() {
      if (testing::UnitTest::GetInstance()->Failed()) return;  // kept to look at
      std::error_code ec;
      for (const auto& d : dirs) fs::remove_all(d, ec);
    }
  };
  static Cleanup cleanup;
#ifndef __EMSCRIPTEN__
  const std::string dir = test::scratch_path(name + "-" + std::to_string(static_cast<long>(::getpid())));
#else
  const std::string dir = test::scratch_path(name);
#endif
  fs::remove_all(dir);
  fs::create_directories(dir);
  cleanup.dirs.push_back(dir);
  return dir;
}

app::ClipLister fake_clips(std::vector<std::string> clips) {
  return [clips](const std::string& path, std::vector<std::string>* out) {
    if (path.find("missing") != std::string::npos) return Status::error(StatusCode::IoError, "cannot open '" + path + "'");
    *out = clips;
    return Status::success();
  };
}

app::BatchManifestResult parse(const std::string& text, const app::ClipLister& clips = fake_clips({"Walk", "Run"})) {
  return app::parse_batch_manifest(text, "/work/m/lib.json", clips);
}

TEST(BatchManifest, ExpandsSourcesClipsTargetsAndPatterns) {
  const auto r = parse(R"({
    "output": "out/{kind}/{target}/{clip}.glb",
    "retarget": [ { "sources": ["chars/Knight.glb"], "clips": "*",
                    "targets": ["chars/Barbarian.glb", {"path": "/abs/woman.ply", "joints": "j.json", "name": "Woman A"}],
                    "options": {"fps": 10, "method": "harmonic"} } ],
    "edit": [ { "input": "bar.ply", "specs": ["bend.json", "twist.json"], "output": "out/edit/{input}-{spec}.{ext}" } ],
    "transfer": [ { "pairs": [ {"reference": "cat-01.ply", "source": "lion.ply", "landmarks": "cl.json"} ],
                    "output": "t/{source}-{reference}.obj", "options": {"method": "levy"} } ],
    "merge": [ { "target": "body.ply", "source": "head.ply", "spec": "m.json", "output": "m/{name}.ply", "name": "x" } ]
  })");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const auto& jobs = r.manifest.jobs;
  ASSERT_EQ(jobs.size(), 4u + 2u + 1u + 1u);
  EXPECT_EQ(r.manifest.summary_path, "/work/m/lib.summary.json");
  // Retarget: source, then target, then clip; outputs from the pattern, ids = the pattern's text.
  EXPECT_EQ(jobs[0].id, "out/retarget/Barbarian/Walk.glb");
  EXPECT_EQ(jobs[0].output, "/work/m/out/retarget/Barbarian/Walk.glb");
  EXPECT_EQ(jobs[1].id, "out/retarget/Barbarian/Run.glb");
  EXPECT_EQ(jobs[2].id, "out/retarget/Woman_A/Walk.glb");
  EXPECT_EQ(jobs[2].files.at("target"), "/abs/woman.ply");
  EXPECT_EQ(jobs[2].files.at("target_joints"), "/work/m/j.json");
  EXPECT_EQ(jobs[2].clip, "Walk");
  EXPECT_EQ(jobs[0].group, jobs[1].group);  // one pair: one precomputation
  EXPECT_NE(jobs[1].group, jobs[2].group);
  EXPECT_EQ(jobs[0].options_json, R"({"fps":10,"method":"harmonic"})");
  EXPECT_EQ(jobs[0].kind, BatchKind::Retarget);
  // The other kinds follow in a fixed order.
  EXPECT_EQ(jobs[4].kind, BatchKind::Transfer);
  EXPECT_EQ(jobs[4].id, "t/lion-cat-01.obj");
  EXPECT_EQ(jobs[5].id, "out/edit/bar-bend.ply");
  EXPECT_EQ(jobs[6].id, "out/edit/bar-twist.ply");
  EXPECT_EQ(jobs[7].id, "m/x.ply");
  for (size_t k = 0; k < jobs.size(); ++k) EXPECT_EQ(jobs[k].index, static_cast<int>(k));
  EXPECT_EQ(app::batch_path_component("a/b c:..\x01"), "a_b_c_.._");
  EXPECT_EQ(app::batch_path_component(".."), "_");
}

TEST(BatchManifest, UnlistableSourceBecomesOneFailedJob) {
  const auto r = parse(R"({"retarget": [ {"sources": ["missing.glb", "ok.glb"], "clips": "*", "target": "t.glb"} ]})");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.manifest.jobs.size(), 3u);
  EXPECT_FALSE(r.manifest.jobs[0].preflight.ok());
  EXPECT_NE(r.manifest.jobs[0].preflight.message.find("cannot list the clips"), std::string::npos);
  EXPECT_TRUE(r.manifest.jobs[1].preflight.ok());
  EXPECT_EQ(r.manifest.jobs[1].id, "out/retarget/t/ok/Walk.glb");  // the default pattern
}

TEST(BatchManifest, RepeatedClipNamesAreWarnedOnce) {
  const auto r = parse(R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb"} ]})",
                       fake_clips({"Idle", "Idle", "Run"}));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.manifest.jobs.size(), 2u);
  ASSERT_EQ(r.manifest.warnings.size(), 1u);
  EXPECT_NE(r.manifest.warnings[0].find("Idle"), std::string::npos);
}

TEST(BatchManifest, ErrorsNameTheProblem) {
  struct Case {
    const char* text;
    const char* expect;
  };
  const Case cases[] = {
      {R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb", "clipz": 1} ]})", "unknown key \"clipz\""},
      {R"({"retargets": []})", "unknown key \"retargets\""},
      {R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb", "options": {"fps": -1}} ]})", "fps"},
      {R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb", "options": {"clip": "Walk"}} ]})", "\"clips\""},
      {R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb", "options": {"no_such": 1}} ]})", "no_such"},
      {R"({"edit": [ {"input": "a.ply", "spec": "b.json", "options": {"weights": "cubic"}} ]})", "weights"},
      {R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb", "output": "o/{clip}.glb"},
                          {"source": "s.glb", "clips": ["Walk"], "target": "u.glb", "output": "o/{clip}.glb"} ]})",
       "both write"},
      {R"({"output": "o/{target}.ply", "edit": [ {"input": "a.ply", "spec": "b.json"} ]})", "uses {target}"},
      {R"({"edit": [ {"input": "a.ply", "spec": "b.json", "output": "o/{input.ply"} ]})", "without '}'"},
      {R"({"edit": [ {"input": "a.ply", "spec": "b.json", "output": "a.ply"} ]})", "is an input"},
      {R"({"retarget": [ {"source": "s.glb", "clips": "*", "target": "t.glb", "output": "o/{clip}.obj"} ]})", ".glb"},
      {R"({"edit": [ {"input": "a.ply", "spec": "b.json", "output": "o/x.txt"} ]})", "unknown format"},
      {R"({"edit": [ {"input": "a.ply"} ]})", "\"specs\""},
      {R"({"comment": "nothing"})", "no jobs"},
      {R"([1, 2])", "must be an object"},
      {R"({"edit": {"input": "a.ply"}})", "array of job groups"},
      {R"({"summary": "s.txt", "edit": [ {"input": "a.ply", "spec": "b.json"} ]})", ".json"},
      {"{\"edit\": [", "not valid JSON"},
  };
  for (const Case& c : cases) {
    const auto r = parse(c.text);
    EXPECT_FALSE(r.status.ok()) << c.text;
    EXPECT_NE(r.status.message.find(c.expect), std::string::npos) << r.status.message;
  }
  // Deep nesting is refused before parsing; a huge key is quoted short.
  const auto deep = parse(std::string(100000, '[') + std::string(100000, ']'));
  EXPECT_EQ(deep.status.code, StatusCode::ParseError);
  EXPECT_NE(deep.status.message.find("deeper"), std::string::npos) << deep.status.message;
  const auto huge = parse("{\"" + std::string(100000, 'k') + "\": 1}");
  EXPECT_EQ(huge.status.code, StatusCode::ParseError);
  EXPECT_LT(huge.status.message.size(), 400u);
}

TEST(BatchState, Sha256KnownAnswers) {
  auto sha = [](const std::string& s) {
    app::Sha256 h;
    h.update(s);
    return h.hex();
  };
  EXPECT_EQ(sha(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  app::Sha256 h;  // in uneven pieces
  const std::string a(1000, 'a');
  for (int i = 0; i < 1000; ++i) h.update(a.data(), a.size());
  EXPECT_EQ(h.hex(), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(BatchState, ShardsPartitionTheJobListOnce) {
  for (int total = 0; total <= 23; ++total)
    for (int n = 1; n <= 7; ++n) {
      std::vector<int> seen;
      for (int i = 0; i < n; ++i) {
        const auto part = app::batch_shard_jobs(total, i, n);
        EXPECT_LE(part.size(), static_cast<size_t>(total / n + 1));
        seen.insert(seen.end(), part.begin(), part.end());
      }
      ASSERT_EQ(seen.size(), static_cast<size_t>(total));
      for (int k = 0; k < total; ++k) EXPECT_EQ(seen[static_cast<size_t>(k)], k);  // contiguous, in order
    }
  int i = 0, n = 0;
  EXPECT_TRUE(app::parse_batch_shard("2/5", &i, &n).ok());
  EXPECT_EQ(i, 2);
  EXPECT_EQ(n, 5);
  for (const char* bad : {"5/5", "1", "-1/3", "a/3", "1/0", "/3", "1/"}) EXPECT_FALSE(app::parse_batch_shard(bad, &i, &n).ok()) << bad;
}

TEST(BatchState, SummaryRoundTripsAndTableSaysWhatFailed) {
  app::BatchSummary s;
  s.manifest = "m.json";
  s.program = app::batch_program_version();
  s.jobs_total = 2;
  s.workers = 2;
  app::BatchJobOutcome a, b;
  a.index = 0, a.id = "out/a.glb", a.kind = "retarget", a.status = "ok", a.output = "/x/out/a.glb";
  a.metrics = {{"frames", 12}, {"bone_length_error_mean", 0.01}, {"flipped_faces_max", 0}};
  a.time_ms = 1234, a.reused = true;
  b.index = 1, b.id = "out/b.ply", b.kind = "edit", b.status = "failed", b.message = "[IoError] cannot open 'x'";
  s.jobs = {a, b};
  app::BatchSummary back;
  ASSERT_TRUE(app::parse_batch_summary(app::batch_summary_json(s), &back).ok());
  EXPECT_EQ(app::batch_summary_json(back), app::batch_summary_json(s));
  const std::string table = app::batch_summary_table(s);
  EXPECT_NE(table.find("FAILED"), std::string::npos) << table;
  EXPECT_NE(table.find("cannot open"), std::string::npos) << table;
  EXPECT_NE(table.find("bone-length err 0.0100"), std::string::npos) << table;
  EXPECT_NE(table.find("1 ok, 0 up to date, 1 failed"), std::string::npos) << table;
  EXPECT_EQ(app::batch_state_path("/a/s.json"), "/a/s.state.json");
  EXPECT_EQ(app::batch_table_path("/a/s.json"), "/a/s.txt");
  EXPECT_EQ(app::batch_shard_summary_path("/a/s.json", 1, 3), "/a/s.shard-1-of-3.json");
}

// Small, fast retarget options for the tests (Fox: 1728 vertices, three clips).
const char* kFastRetarget = R"({"fps": 5, "last_frame": 3, "num_singularities": 120, "num_collocation": 600, "surface_descriptors": 100})";

app::BatchJob retarget_job(const std::string& out_dir, const std::string& clip, int index) {
  app::BatchJob j;
  j.index = index;
  j.kind = BatchKind::Retarget;
  j.id = clip + ".glb";
  j.files["source"] = test::data_path("anim/Fox/glTF-Binary/Fox.glb");
  j.files["target"] = test::data_path("anim/wolf0.ply");
  j.files["target_joints"] = test::data_path("joints/wolf0_joints.json");
  j.clip = clip;
  j.options_json = Json::parse(kFastRetarget).dump();
  j.output = out_dir + "/" + clip + ".glb";
  j.group = "fox-wolf";
  return j;
}

// The worker prepares a pair once and samples each clip itself: its GLB must be the bytes
// RetargetJob (what `meshmorph retarget --clip` runs) writes for that clip.
TEST(BatchWorker, SharedPrecomputationWritesTheSameBytesAsRetargetJob) {
  const std::string dir = fresh_dir("batch-worker");
  app::BatchWorker worker;
  const app::BatchJobOutcome first = worker.run(retarget_job(dir, "Survey", 0));
  ASSERT_EQ(first.status, "ok") << first.message;
  EXPECT_FALSE(first.reused);
  const app::BatchJobOutcome walk = worker.run(retarget_job(dir, "Walk", 1));
  ASSERT_EQ(walk.status, "ok") << walk.message;
  EXPECT_TRUE(walk.reused);
  EXPECT_EQ(walk.precompute_ms, 0);
  EXPECT_EQ(walk.metrics["frames"], 3);
  EXPECT_LT(walk.metrics["bone_length_error_mean"].get<double>(), 0.2);
  EXPECT_TRUE(walk.metrics.contains("flipped_faces_max"));
  const app::BatchJobOutcome bad = worker.run(retarget_job(dir, "NoSuchClip", 2));
  EXPECT_EQ(bad.status, "failed");
  EXPECT_NE(bad.message.find("NoSuchClip"), std::string::npos) << bad.message;

  // The same clip through RetargetJob, as the CLI runs it.
  const io::LoadResult src = io::load_asset(test::data_path("anim/Fox/glTF-Binary/Fox.glb"));
  const io::LoadResult tgt = io::load_asset(test::data_path("anim/wolf0.ply"));
  app::RetargetJobOptions opt;
  ASSERT_TRUE(app::set_options_from_json(Json::parse(kFastRetarget), app::retarget_options(), &opt, "t").ok());
  opt.clip = "Walk";
  app::RetargetJob session;
  ASSERT_TRUE(session.prepare(src.asset, tgt.asset, read_text(test::data_path("joints/wolf0_joints.json")), "", opt).ok());
  std::vector<Eigen::MatrixXd> frames;
  ASSERT_TRUE(session.frames(0, session.num_frames(), &frames).ok());
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(session.write_glb(frames, session.times(), &bytes).ok());
  const std::string batch_bytes = read_text(dir + "/Walk.glb");
  EXPECT_EQ(batch_bytes.size(), bytes.size());
  EXPECT_TRUE(batch_bytes == std::string(bytes.begin(), bytes.end())) << "the worker's GLB differs from RetargetJob's";
}

TEST(BatchWorker, FlipCounterCountsAsTransferMetrics) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(3, &V, &F);
  const app::FlipCounter flips(V, F);
  EXPECT_EQ(flips.count(V), 0);
  // Rotated: nothing flips; two vertices of an edge swapped turn the faces around it over.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_EQ(flips.count(V * R.transpose()), 0);
  Eigen::MatrixXd W = V;
  for (int f = 0; f < F.rows(); f += 97) W.row(F(f, 0)).swap(W.row(F(f, 1)));
  const int n = flips.count(W);
  EXPECT_GT(n, 10);
  EXPECT_EQ(n, transfer_metrics(W, V, F).flipped_faces);
}

TEST(BatchWorker, JobMessagesRoundTrip) {
  app::BatchJob j = retarget_job("/tmp", "Walk", 7);
  app::BatchJob back;
  ASSERT_TRUE(app::parse_batch_job_message(app::batch_job_message(j), &back).ok());
  EXPECT_EQ(back.index, 7);
  EXPECT_EQ(back.files, j.files);
  EXPECT_EQ(back.options_json, j.options_json);
  EXPECT_EQ(back.output, j.output);
  EXPECT_EQ(back.group, j.group);
  EXPECT_FALSE(app::parse_batch_job_message("{\"index\": 1}", &back).ok());
  EXPECT_FALSE(app::parse_batch_job_message("not json", &back).ok());
}

#ifndef __EMSCRIPTEN__

// ---- whole batches through the CLI binary

std::string meshmorph_binary() {
  if (const char* env = std::getenv("MESHMORPH_BIN")) return env;
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "meshmorph";
  // build/<target>/tests/meshmorph_tests → build/<target>/native/meshmorph
  return (fs::path(std::string(buf, static_cast<size_t>(n))).parent_path().parent_path() / "native" / "meshmorph").string();
}

// Runs `meshmorph <args>` through the shell in `dir`; returns its exit code.
int meshmorph(const std::string& dir, const std::string& args, const std::string& env = "") {
  const std::string cmd = "cd '" + dir + "' && " + env + " '" + meshmorph_binary() + "' " + args + " >batch-stdout.txt 2>batch-stderr.txt";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A small cap (hemisphere) for the merge job onto data/edit/cylinder_coarse.ply's first loop,
// and the merge spec with two keys on each loop.
void write_merge_inputs(const std::string& dir) {
  const Mesh cyl = test::load_mesh("edit/cylinder_coarse.ply");
  const auto tl = boundary_loops(cyl.F, cyl.num_vertices());
  ASSERT_EQ(tl.size(), 2u);
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(2, &V, &F);
  const CutResult cap = cut_plane(V, F, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 1, 0));
  ASSERT_TRUE(cap.status.ok()) << cap.status.message;
  ASSERT_TRUE(io::save_mesh(dir + "/cap.ply", cap.V, cap.F).ok());
  const auto sl = boundary_loops(cap.F, static_cast<int>(cap.V.rows()));
  ASSERT_EQ(sl.size(), 1u);
  const auto& t = tl[0];
  const auto& s = sl[0];
  Json spec;
  spec["pairs"] = Json::array({Json{{"target_keys", {t[0], t[t.size() / 2]}}, {"source_keys", {s[0], s[s.size() / 2]}}}});
  write_text(dir + "/cap-on-cylinder.json", spec.dump());
}

// Retarget (Fox → itself: self-retargeting error; Fox → wolf0 with a joints file), two edits
// and a merge: 3·2 + 2 + 1 = 9 jobs.
std::string library_manifest(const std::string& inputs, const std::string& extra_edit = "") {
  Json m;
  m["summary"] = "out/summary.json";
  m["retarget"] = Json::array({Json{
      {"source", test::data_path("anim/Fox/glTF-Binary/Fox.glb")},
      {"clips", "*"},
      {"targets", Json::array({test::data_path("anim/Fox/glTF-Binary/Fox.glb"),
                               Json{{"path", test::data_path("anim/wolf0.ply")},
                                    {"joints", test::data_path("joints/wolf0_joints.json")}}})},
      {"options", Json::parse(kFastRetarget)},
      {"output", "out/retarget/{target}/{clip}.glb"}}});
  Json edits = Json::array({Json{{"input", test::data_path("edit/bar.ply")},
                                 {"specs", {test::data_path("specs/bar_bend.json"), test::data_path("specs/bar_twist.json")}},
                                 {"output", "out/edit/{spec}.ply"}}});
  if (!extra_edit.empty()) edits.push_back(Json::parse(extra_edit));
  m["edit"] = edits;
  m["merge"] = Json::array({Json{{"target", test::data_path("edit/cylinder_coarse.ply")},
                                 {"source", inputs + "/cap.ply"},
                                 {"spec", inputs + "/cap-on-cylinder.json"},
                                 {"output", "out/merge/{source}-on-{target}.ply"}}});
  return m.dump(1);
}

Json summary_of(const std::string& dir) { return Json::parse(read_text(dir + "/out/summary.json")); }

int count_status(const Json& summary, const std::string& status) {
  int n = 0;
  for (const Json& j : summary["jobs"]) n += j["status"] == status;
  return n;
}

// The reproducible part of a summary: every job's row without its timing.
Json without_timing(const Json& summary) {
  Json jobs = summary["jobs"];
  for (Json& j : jobs) j.erase("timing");
  return jobs;
}

// Every file under dir/out except summaries and state (outputs only), relative path → bytes.
std::map<std::string, std::string> outputs_of(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir + "/out")) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), dir + "/out").string();
    if (rel.rfind("summary", 0) == 0) continue;
    out[rel] = read_text(e.path().string());
  }
  return out;
}

// One clean run of the library manifest, shared by the tests below (built once).
const std::string& clean_run() {
  static const std::string dir = [] {
    const std::string d = fresh_dir("batch-clean");
    write_merge_inputs(d);
    write_text(d + "/lib.json", library_manifest(d));
    const int code = meshmorph(d, "batch lib.json --jobs 2");
    EXPECT_EQ(code, 0) << read_text(d + "/batch-stderr.txt") << read_text(d + "/batch-stdout.txt");
    fs::copy_file(d + "/out/summary.json", d + "/clean-summary.json");  // before any test runs it again
    return d;
  }();
  return dir;
}

TEST(BatchRun, CleanRunReportsEveryJobAndItsMetrics) {
  const std::string& dir = clean_run();
  const Json s = Json::parse(read_text(dir + "/clean-summary.json"));
  ASSERT_EQ(s["jobs"].size(), 9u);
  EXPECT_EQ(count_status(s, "ok"), 9) << s.dump(1);
  for (const Json& j : s["jobs"]) {
    EXPECT_TRUE(fs::exists(j["output"].get<std::string>())) << j["output"];
    if (j["kind"] == "retarget") {
      EXPECT_EQ(j["metrics"]["frames"], 3);
      EXPECT_TRUE(j["metrics"].contains("bone_length_error_mean"));
      EXPECT_TRUE(j["metrics"].contains("flipped_faces_max"));
    }
  }
  // Fox onto itself: self-retargeting error (Eq. 19) is reported, and small.
  const Json& self = s["jobs"][0];
  ASSERT_TRUE(self["metrics"].contains("self_retargeting_error")) << self.dump(1);
  EXPECT_LT(self["metrics"]["self_retargeting_error"].get<double>(), 0.05);
  EXPECT_TRUE(s["jobs"][6]["metrics"].contains("rigidity_error"));
  EXPECT_EQ(s["jobs"][8]["metrics"]["boundary_loops"], 1);  // the cap closed one end of the tube
  // Two of each pair's three clips reused the pair's precomputation (each pair went to one worker).
  int reused = 0;
  for (const Json& j : s["jobs"]) reused += j["timing"]["reused"].get<bool>();
  EXPECT_GE(reused, 2);
  const std::string table = read_text(dir + "/out/summary.txt");
  EXPECT_NE(table.find("9 ok, 0 up to date, 0 failed"), std::string::npos) << table;
  EXPECT_NE(table.find("self-retargeting err"), std::string::npos) << table;

  // A second run has nothing to do; a changed input re-runs only its jobs.
  EXPECT_EQ(meshmorph(dir, "batch lib.json"), 0);
  EXPECT_EQ(count_status(summary_of(dir), "up-to-date"), 9);
  const std::string other = fresh_dir("batch-rerun");
  for (const char* f : {"cap.ply", "cap-on-cylinder.json"}) fs::copy_file(dir + "/" + f, other + "/" + f);
  write_text(other + "/lib.json", library_manifest(other));
  fs::copy(dir + "/out", other + "/out", fs::copy_options::recursive);
  // (copied outputs have new times: the state of `dir` does not vouch for them)
  EXPECT_EQ(meshmorph(other, "batch lib.json --dry-run"), 0);
  EXPECT_NE(read_text(other + "/batch-stdout.txt").find("to-run"), std::string::npos);
}

TEST(BatchRun, BrokenAndCrashingJobsFailAloneAndTheExitCodeSaysSo) {
  const std::string dir = fresh_dir("batch-broken");
  write_merge_inputs(dir);
  // A missing input, a clip that does not exist, and a job whose worker dies (SIGABRT).
  Json m = Json::parse(library_manifest(dir, R"({"input": "no-such-mesh.ply", "spec": ")" +
                                                 test::data_path("specs/bar_bend.json") + R"(", "output": "out/edit/missing.ply"})"));
  m["retarget"][0]["clips"] = {"Walk", "NoSuchClip"};
  write_text(dir + "/lib.json", m.dump(1));
  const int code = meshmorph(dir, "batch lib.json --jobs 2", "MESHMORPH_BATCH_CRASH=out/edit/bar_twist.ply");
  EXPECT_EQ(code, 1) << read_text(dir + "/batch-stderr.txt");
  const Json s = summary_of(dir);
  std::map<std::string, Json> by_id;
  for (const Json& j : s["jobs"]) by_id[j["id"]] = j;
  ASSERT_EQ(by_id.size(), 2u * 2 + 3 + 1);  // clips × targets, edits, merge
  EXPECT_EQ(by_id["out/edit/missing.ply"]["status"], "failed");
  EXPECT_NE(by_id["out/edit/missing.ply"]["message"].get<std::string>().find("no-such-mesh"), std::string::npos);
  EXPECT_EQ(by_id["out/retarget/wolf0/NoSuchClip.glb"]["status"], "failed");
  EXPECT_NE(by_id["out/retarget/wolf0/NoSuchClip.glb"]["message"].get<std::string>().find("Walk"), std::string::npos)
      << "the error lists the clips there are";
  EXPECT_EQ(by_id["out/edit/bar_twist.ply"]["status"], "failed");
  EXPECT_NE(by_id["out/edit/bar_twist.ply"]["message"].get<std::string>().find("[Crash]"), std::string::npos)
      << by_id["out/edit/bar_twist.ply"].dump();
  EXPECT_EQ(count_status(s, "ok"), 4);
  for (const char* ok : {"out/retarget/Fox/Walk.glb", "out/retarget/wolf0/Walk.glb", "out/edit/bar_bend.ply",
                         "out/merge/cap-on-cylinder_coarse.ply"})
    EXPECT_EQ(by_id[ok]["status"], "ok") << ok;
  // The others' outputs equal the clean run's.
  const auto clean = outputs_of(clean_run());
  EXPECT_EQ(read_text(dir + "/out/retarget/wolf0/Walk.glb"), clean.at("retarget/wolf0/Walk.glb"));
  EXPECT_NE(read_text(dir + "/out/summary.txt").find("FAILED"), std::string::npos);
  // No temporary file of the crashed job is left.
  for (const auto& e : fs::recursive_directory_iterator(dir + "/out"))
    EXPECT_EQ(e.path().string().find(".mm-tmp-"), std::string::npos) << e.path();
  // A re-run retries only the failures (the crash is gone now).
  EXPECT_EQ(meshmorph(dir, "batch lib.json --jobs 2"), 1);
  const Json again = summary_of(dir);
  EXPECT_EQ(count_status(again, "up-to-date"), 4);
  EXPECT_EQ(count_status(again, "ok"), 1);  // bar-twist
  EXPECT_EQ(count_status(again, "failed"), 3);
}

TEST(BatchRun, KilledMidwayResumesWithOnlyTheUnfinishedJobs) {
  const std::string dir = fresh_dir("batch-killed");
  write_merge_inputs(dir);
  write_text(dir + "/lib.json", library_manifest(dir));
  const std::string state = dir + "/out/summary.state.json";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1), ::dup2(devnull, 2);
    const std::string exe = meshmorph_binary();
    ::execl(exe.c_str(), exe.c_str(), "batch", "lib.json", "--jobs", "1", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Kill the batch (and with it its worker) once two jobs are recorded.
  size_t recorded = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(300)) {
    if (fs::exists(state)) {
      const Json st = Json::parse(read_text(state), nullptr, false);
      if (!st.is_discarded() && st["jobs"].size() >= 2) {
        ::kill(pid, SIGKILL);
        break;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  int wstatus = 0;
  ::waitpid(pid, &wstatus, 0);
  ASSERT_TRUE(WIFSIGNALED(wstatus)) << "the batch finished before it was killed";
  recorded = Json::parse(read_text(state))["jobs"].size();
  ASSERT_GE(recorded, 2u);
  ASSERT_LT(recorded, 9u);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the worker dies with its parent (PDEATHSIG)

  EXPECT_EQ(meshmorph(dir, "batch lib.json --jobs 2"), 0) << read_text(dir + "/batch-stderr.txt");
  const Json s = summary_of(dir);
  EXPECT_EQ(count_status(s, "up-to-date"), static_cast<int>(recorded));
  EXPECT_EQ(count_status(s, "ok"), 9 - static_cast<int>(recorded));
  EXPECT_EQ(without_timing(s).size(), 9u);
  // Byte-equal to a clean run, and no temporary files left over.
  EXPECT_EQ(outputs_of(dir), outputs_of(clean_run()));
}

TEST(BatchRun, ShardsGatheredEqualTheUnshardedRun) {
  const std::string dir = fresh_dir("batch-shards");
  write_merge_inputs(dir);
  write_text(dir + "/lib.json", library_manifest(dir));
  for (int i = 0; i < 3; ++i)
    ASSERT_EQ(meshmorph(dir, "batch lib.json --jobs 1 --shard " + std::to_string(i) + "/3"), 0)
        << read_text(dir + "/batch-stderr.txt");
  // A gather with a shard missing fails and names the missing jobs.
  fs::rename(dir + "/out/summary.shard-1-of-3.json", dir + "/shard1.json");
  EXPECT_EQ(meshmorph(dir, "batch lib.json --gather"), 1);
  EXPECT_EQ(count_status(summary_of(dir), "not-run"), 3);
  fs::rename(dir + "/shard1.json", dir + "/out/summary.shard-1-of-3.json");
  ASSERT_EQ(meshmorph(dir, "batch lib.json --gather"), 0) << read_text(dir + "/batch-stderr.txt");
  const Json gathered = summary_of(dir), clean = Json::parse(read_text(clean_run() + "/clean-summary.json"));
  // Statuses, outputs and metrics (everything but timing) equal the unsharded run's; so do the files.
  Json a = without_timing(gathered), b = without_timing(clean);
  for (Json* x : {&a, &b})
    for (Json& j : *x) j["output"] = fs::relative(j["output"].get<std::string>(), x == &a ? dir : clean_run()).string();
  EXPECT_EQ(a, b);
  auto files = outputs_of(dir), clean_files = outputs_of(clean_run());
  for (auto it = files.begin(); it != files.end();)  // shard summaries, states and tables
    it = it->first.find("summary") != std::string::npos ? files.erase(it) : std::next(it);
  EXPECT_EQ(files, clean_files);
  // The gathered state makes the whole manifest up to date.
  EXPECT_EQ(meshmorph(dir, "batch lib.json"), 0);
  EXPECT_EQ(count_status(summary_of(dir), "up-to-date"), 9);
}

// The Slurm path without Slurm: the generated array script runs each task (as sbatch would, with
// SLURM_ARRAY_TASK_ID set), then the gather script; the result equals the local run.
TEST(BatchRun, SlurmScriptsRunByHandEqualTheLocalRun) {
  const std::string dir = fresh_dir("batch-slurm");
  write_merge_inputs(dir);
  write_text(dir + "/lib.json", library_manifest(dir));
  ASSERT_EQ(meshmorph(dir, "batch lib.json --slurm --shards 2 --jobs 1"), 0) << read_text(dir + "/batch-stderr.txt");
  const std::string array = read_text(dir + "/out/summary.slurm-array.sh");
  EXPECT_NE(array.find("#SBATCH --array=0-1"), std::string::npos) << array;
  EXPECT_NE(array.find("--shard \"${SLURM_ARRAY_TASK_ID}/2\""), std::string::npos) << array;
  EXPECT_NE(read_text(dir + "/out/summary.slurm-submit.sh").find("--dependency=afterany:"), std::string::npos);
  // Both tasks at once, as Slurm starts them: they race to create the same output folders (the
  // seventeenth submission's CI failure: one task found out/retarget/Fox missing, the other made it,
  // and create_directories' "nothing created" was taken for a failure).
  std::string cmd = "cd '" + dir + "' || exit 1; ";
  for (int i = 0; i < 2; ++i)
    cmd += "(SLURM_ARRAY_TASK_ID=" + std::to_string(i) + " SLURM_CPUS_PER_TASK=1 bash out/summary.slurm-array.sh >task" +
           std::to_string(i) + ".txt 2>&1) & p" + std::to_string(i) + "=$!; ";
  cmd += "wait $p0 && wait $p1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << read_text(dir + "/task0.txt") << read_text(dir + "/task1.txt");
  ASSERT_EQ(std::system(("cd '" + dir + "' && bash out/summary.slurm-gather.sh >/dev/null 2>&1").c_str()), 0);
  const Json gathered = summary_of(dir);
  EXPECT_EQ(count_status(gathered, "ok"), 9);
  auto files = outputs_of(dir);
  for (auto it = files.begin(); it != files.end();)
    it = it->first.find("summary") != std::string::npos ? files.erase(it) : std::next(it);
  EXPECT_EQ(files, outputs_of(clean_run()));
}

#else

TEST(BatchRun, NeedsWorkerProcesses) { GTEST_SKIP() << "batch runs fork/exec worker processes: native only"; }

#endif

}  // namespace
}  // namespace mm
