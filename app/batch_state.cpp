#include "app/batch_state.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include "io/asset.h"
#include "io/gltf_uri.h"
#include "io/json_text.h"

#ifndef MM_PROGRAM_VERSION
#define MM_PROGRAM_VERSION "dev"
#endif

namespace mm::app {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// ---- SHA-256 (FIPS 180-4)

namespace {
constexpr uint32_t kSha256K[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

inline uint32_t rotr(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }
}  // namespace

Sha256::Sha256()
    : h_{0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19} {}

void Sha256::block(const uint8_t* p) {
  uint32_t w[64];
  for (int i = 0; i < 16; ++i)
    w[i] = uint32_t(p[4 * i]) << 24 | uint32_t(p[4 * i + 1]) << 16 | uint32_t(p[4 * i + 2]) << 8 | uint32_t(p[4 * i + 3]);
  for (int i = 16; i < 64; ++i) {
    const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
    const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
    w[i] = w[i - 16] + s0 + w[i - 7] + s1;
  }
  uint32_t a = h_[0], b = h_[1], c = h_[2], d = h_[3], e = h_[4], f = h_[5], g = h_[6], h = h_[7];
  for (int i = 0; i < 64; ++i) {
    const uint32_t t1 = h + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + kSha256K[i] + w[i];
    const uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    h = g;
    g = f;
    f = e;
    e = d + t1;
    d = c;
    c = b;
    b = a;
    a = t1 + t2;
  }
  h_[0] += a, h_[1] += b, h_[2] += c, h_[3] += d, h_[4] += e, h_[5] += f, h_[6] += g, h_[7] += h;
}

void Sha256::update(const void* data, size_t n) {
  const uint8_t* p = static_cast<const uint8_t*>(data);
  bytes_ += n;
  while (n > 0) {
    if (fill_ == 0 && n >= 64) {
      block(p);
      p += 64;
      n -= 64;
      continue;
    }
    const size_t take = std::min(n, 64 - fill_);
    std::memcpy(buf_ + fill_, p, take);
    fill_ += take;
    p += take;
    n -= take;
    if (fill_ == 64) {
      block(buf_);
      fill_ = 0;
    }
  }
}

std::string Sha256::hex() {
  const uint64_t bits = bytes_ * 8;
  const uint8_t one = 0x80, zero = 0;
  update(&one, 1);
  while (fill_ != 56) update(&zero, 1);
  uint8_t len[8];
  for (int i = 0; i < 8; ++i) len[i] = static_cast<uint8_t>(bits >> (56 - 8 * i));
  update(len, 8);
  char out[65];
  for (int i = 0; i < 8; ++i) std::snprintf(out + 8 * i, 9, "%08x", h_[i]);
  return std::string(out, 64);
}

std::string batch_program_version() { return std::string("meshmorph ") + MM_PROGRAM_VERSION; }

// ---- keys

const std::string& FileHashCache::hash(const std::string& path) {
  auto it = cache_.find(path);
  if (it != cache_.end()) return it->second;
  std::string& out = cache_[path];
  std::vector<uint8_t> bytes;
  if (!io::read_file(path, &bytes).ok()) return out;
  Sha256 h;
  h.update(bytes.data(), bytes.size());
  // A .gltf's meaning includes the buffers and images it names.
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".gltf") {
    const std::string text(bytes.begin(), bytes.end());
    if (io::check_json_depth(text, "glTF").ok()) {
      const Json j = Json::parse(text, nullptr, false);
      for (const char* list : {"buffers", "images"}) {
        if (!j.is_object() || !j.contains(list) || !j[list].is_array()) continue;
        for (const Json& e : j[list]) {
          if (!e.is_object() || !e.contains("uri") || !e["uri"].is_string()) continue;
          const std::string uri = e["uri"].get<std::string>();
          if (io::is_data_uri(uri)) continue;
          const std::string decoded = io::uri_decode(uri);
          if (!io::check_relative_uri(decoded, "uri").ok()) continue;
          std::vector<uint8_t> side;
          if (!io::read_file((fs::path(path).parent_path() / decoded).string(), &side).ok()) {
            out.clear();
            return out;  // the load will fail and say why
          }
          h.update(decoded + "\n");
          h.update(side.data(), side.size());
        }
      }
    }
  }
  out = h.hex();
  return out;
}

std::string batch_job_key(const BatchJob& job, FileHashCache* files) {
  Sha256 h;
  h.update("meshmorph batch job v1\n" + batch_program_version() + "\n" + batch_kind_name(job.kind) + "\nclip " + job.clip +
           "\noptions " + job.options_json + "\n");
  for (const auto& [role, path] : job.files) {
    const std::string& fh = files->hash(path);
    if (fh.empty()) return "";
    h.update(role + " " + fh + "\n");
  }
  return h.hex();
}

// ---- summary

int BatchSummary::count(const std::string& status) const {
  return static_cast<int>(std::count_if(jobs.begin(), jobs.end(), [&](const BatchJobOutcome& o) { return o.status == status; }));
}

namespace {

Json outcome_json(const BatchJobOutcome& o) {
  Json j;
  j["index"] = o.index;
  j["id"] = o.id;
  j["label"] = o.label;
  j["kind"] = o.kind;
  j["status"] = o.status;
  j["output"] = o.output;
  if (!o.message.empty()) j["message"] = o.message;
  j["metrics"] = o.metrics;
  if (!o.warnings.empty()) j["warnings"] = o.warnings;
  j["timing"] = {{"time_ms", o.time_ms}, {"precompute_ms", o.precompute_ms}, {"reused", o.reused}};
  return j;
}

bool outcome_from_json(const Json& j, BatchJobOutcome* o) {
  if (!j.is_object() || !j.contains("index") || !j["index"].is_number_integer() || !j.contains("id") ||
      !j["id"].is_string() || !j.contains("status") || !j["status"].is_string())
    return false;
  o->index = j["index"].get<int>();
  o->id = j["id"].get<std::string>();
  o->label = j.value("label", "");
  o->kind = j.value("kind", "");
  o->status = j["status"].get<std::string>();
  o->output = j.value("output", "");
  o->message = j.value("message", "");
  if (j.contains("metrics") && j["metrics"].is_object()) o->metrics = j["metrics"];
  if (j.contains("warnings") && j["warnings"].is_array())
    for (const Json& w : j["warnings"])
      if (w.is_string()) o->warnings.push_back(w.get<std::string>());
  if (j.contains("timing") && j["timing"].is_object()) {
    const Json& t = j["timing"];
    o->time_ms = t.value("time_ms", 0.0);
    o->precompute_ms = t.value("precompute_ms", 0.0);
    o->reused = t.value("reused", false);
  }
  return true;
}

std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

std::string duration_text(double ms) {
  if (ms < 1000) return fmt("%.0f ms", ms);
  if (ms < 60000) return fmt("%.1f s", ms / 1000);
  return fmt("%.0f min ", std::floor(ms / 60000)) + fmt("%.0f s", std::fmod(ms, 60000) / 1000);
}

// The main metrics of a row, short.
std::string metrics_text(const Json& m) {
  struct Item {
    const char* key;
    const char* label;
    const char* format;
  };
  static const Item items[] = {
      {"frames", "frames", "%.0f"},
      {"self_retargeting_error", "self-retargeting err", "%.4f"},
      {"ground_truth_error", "ground-truth err", "%.4f"},
      {"bone_length_error_mean", "bone-length err", "%.4f"},
      {"bone_length_error_max", "max", "%.3f"},
      {"flipped_faces_max", "flipped faces (max/frame)", "%.0f"},
      {"flipped_faces", "flipped faces", "%.0f"},
      {"inverted_faces", "inverted faces", "%.0f"},
      {"rigidity_error", "rigidity err", "%.4f"},
      {"edge_distortion_mean", "edge distortion", "%.4f"},
      {"laplacian_change", "detail change", "%.4f"},
      {"boundary_loops", "boundary loops", "%.0f"},
      {"nonmanifold_edges", "non-manifold edges", "%.0f"},
      {"seam_flipped_faces", "seam flipped", "%.0f"},
  };
  std::string out;
  for (const Item& it : items) {
    if (!m.contains(it.key) || !m[it.key].is_number()) continue;
    out += (out.empty() ? "" : std::string(it.key) == "bone_length_error_max" ? " " : ", ") + std::string(it.label) + " " +
           fmt(it.format, m[it.key].get<double>());
  }
  return out;
}

}  // namespace

std::string batch_summary_json(const BatchSummary& s) {
  Json j;
  j["manifest"] = s.manifest;
  j["program"] = s.program;
  if (s.shard_count > 0) j["shard"] = {{"index", s.shard_index}, {"count", s.shard_count}};
  j["jobs_total"] = s.jobs_total;
  j["counts"] = {{"ok", s.count("ok")},
                 {"up_to_date", s.count("up-to-date")},
                 {"failed", s.count("failed")},
                 {"not_run", s.count("not-run")}};
  j["workers"] = s.workers;
  j["wall_ms"] = s.wall_ms;
  if (!s.warnings.empty()) j["warnings"] = s.warnings;
  j["jobs"] = Json::array();
  for (const BatchJobOutcome& o : s.jobs) j["jobs"].push_back(outcome_json(o));
  return j.dump(1) + "\n";
}

Status parse_batch_summary(const std::string& text, BatchSummary* s) {
  if (Status d = io::check_json_depth(text, "batch summary"); !d.ok()) return d;
  const Json j = Json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("jobs") || !j["jobs"].is_array())
    return Status::error(StatusCode::ParseError, "not a batch summary (JSON with a \"jobs\" array)");
  try {
    s->manifest = j.value("manifest", "");
    s->program = j.value("program", "");
    s->jobs_total = j.value("jobs_total", 0);
    s->workers = j.value("workers", 0);
    s->wall_ms = j.value("wall_ms", 0.0);
    if (j.contains("shard") && j["shard"].is_object()) {
      s->shard_index = j["shard"].value("index", -1);
      s->shard_count = j["shard"].value("count", 0);
    }
    if (j.contains("warnings") && j["warnings"].is_array())
      for (const Json& w : j["warnings"])
        if (w.is_string()) s->warnings.push_back(w.get<std::string>());
    for (const Json& e : j["jobs"]) {
      BatchJobOutcome o;
      if (!outcome_from_json(e, &o)) return Status::error(StatusCode::ParseError, "batch summary: a job entry lacks index, id or status");
      s->jobs.push_back(std::move(o));
    }
  } catch (const std::exception& e) {
    return Status::error(StatusCode::ParseError, io::cap_message(std::string("batch summary: ") + e.what()));
  }
  return Status::success();
}

std::string batch_summary_table(const BatchSummary& s) {
  size_t wide = 6;
  for (const BatchJobOutcome& o : s.jobs) wide = std::max(wide, std::min<size_t>(o.id.size(), 70));
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-10s  %9s  %-*s  %s\n", "status", "time", int(wide), "output", "metrics / message");
  out += line;
  for (const BatchJobOutcome& o : s.jobs) {
    std::string what = o.status == "failed" || o.status == "not-run" ? o.message : metrics_text(o.metrics);
    if (o.reused) what += (what.empty() ? "" : "; ") + std::string("shared precompute");
    std::snprintf(line, sizeof line, "%-10s  %9s  %-*s  ", o.status == "failed" ? "FAILED" : o.status.c_str(),
                  o.status == "not-run" || o.status == "to-run" ? "-" : duration_text(o.time_ms).c_str(), int(wide), o.id.c_str());
    out += line + what + "\n";
  }
  std::snprintf(line, sizeof line, "%d job(s)%s: %d ok, %d up to date, %d failed, %d not run; wall %s with %d worker(s)\n",
                int(s.jobs.size()),
                s.shard_count > 0 ? (" (shard " + std::to_string(s.shard_index) + "/" + std::to_string(s.shard_count) + ")").c_str() : "",
                s.count("ok"), s.count("up-to-date"), s.count("failed"), s.count("not-run"), duration_text(s.wall_ms).c_str(),
                s.workers);
  out += line;
  if (const int n = s.count("to-run"); n > 0) out += std::to_string(n) + " job(s) to run (--dry-run: nothing ran)\n";
  for (const std::string& w : s.warnings) out += "warning: " + w + "\n";
  return out;
}

// ---- state

namespace {
bool stat_file(const std::string& path, uint64_t* size, int64_t* mtime_ns) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  *size = static_cast<uint64_t>(st.st_size);
#if defined(__APPLE__)
  *mtime_ns = int64_t(st.st_mtimespec.tv_sec) * 1000000000 + st.st_mtimespec.tv_nsec;
#else
  *mtime_ns = int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
#endif
  return true;
}
}  // namespace

BatchState read_batch_state(const std::string& path, std::string* warning) {
  BatchState state;
  std::error_code ec;
  if (!fs::exists(path, ec)) return state;
  std::vector<uint8_t> bytes;
  const Status s = io::read_file(path, &bytes);
  const std::string text(bytes.begin(), bytes.end());
  const Json j = s.ok() && io::check_json_depth(text, "state").ok() ? Json::parse(text, nullptr, false) : Json();
  if (!j.is_object() || j.value("format", "") != "meshmorph-batch-state-1" || !j.contains("jobs") || !j["jobs"].is_object()) {
    if (warning) *warning = "state file '" + io::quote_input(path, 200) + "' is unreadable; every job runs";
    return state;
  }
  try {
    for (auto it = j["jobs"].begin(); it != j["jobs"].end(); ++it) {
      const Json& e = it.value();
      if (!e.is_object()) continue;
      BatchStateEntry entry;
      entry.key = e.value("key", "");
      entry.output = e.value("output", "");
      entry.size = e.value("size", uint64_t{0});
      entry.mtime_ns = e.value("mtime_ns", int64_t{0});
      if (e.contains("metrics") && e["metrics"].is_object()) entry.metrics = e["metrics"];
      if (e.contains("warnings") && e["warnings"].is_array())
        for (const Json& w : e["warnings"])
          if (w.is_string()) entry.warnings.push_back(w.get<std::string>());
      entry.time_ms = e.value("time_ms", 0.0);
      state[it.key()] = std::move(entry);
    }
  } catch (const std::exception&) {
    if (warning) *warning = "state file '" + io::quote_input(path, 200) + "' is malformed; every job runs";
    return {};
  }
  return state;
}

Status write_batch_state(const std::string& path, const BatchState& state) {
  Json j;
  j["format"] = "meshmorph-batch-state-1";
  j["program"] = batch_program_version();
  j["jobs"] = Json::object();
  for (const auto& [id, e] : state) {
    Json x;
    x["key"] = e.key;
    x["output"] = e.output;
    x["size"] = e.size;
    x["mtime_ns"] = e.mtime_ns;
    x["metrics"] = e.metrics;
    if (!e.warnings.empty()) x["warnings"] = e.warnings;
    x["time_ms"] = e.time_ms;
    j["jobs"][id] = x;
  }
  const std::string text = j.dump(1) + "\n";
  return io::write_file_atomic(path, std::vector<uint8_t>(text.begin(), text.end()));
}

BatchStateEntry batch_state_entry(const BatchJobOutcome& o, const std::string& key) {
  BatchStateEntry e;
  e.key = key;
  e.output = o.output;
  e.metrics = o.metrics;
  e.warnings = o.warnings;
  e.time_ms = o.time_ms;
  if (!stat_file(o.output, &e.size, &e.mtime_ns)) e.key.clear();  // no output: never current
  return e;
}

bool batch_output_current(const BatchStateEntry& e, const std::string& key, const std::string& output) {
  if (key.empty() || e.key != key || e.output != output) return false;
  uint64_t size = 0;
  int64_t mtime = 0;
  return stat_file(output, &size, &mtime) && size == e.size && mtime == e.mtime_ns;
}

namespace {
std::string without_json(const std::string& summary_path) {
  const size_t n = summary_path.size();
  return n > 5 && summary_path.compare(n - 5, 5, ".json") == 0 ? summary_path.substr(0, n - 5) : summary_path;
}
}  // namespace

std::string batch_state_path(const std::string& summary_path) { return without_json(summary_path) + ".state.json"; }
std::string batch_table_path(const std::string& summary_path) { return without_json(summary_path) + ".txt"; }
std::string batch_shard_summary_path(const std::string& summary_path, int index, int count) {
  return without_json(summary_path) + ".shard-" + std::to_string(index) + "-of-" + std::to_string(count) + ".json";
}

// ---- shards

std::vector<int> batch_shard_jobs(int total, int index, int count) {
  std::vector<int> out;
  if (count <= 0 || index < 0 || index >= count) return out;
  const int64_t a = int64_t(total) * index / count, b = int64_t(total) * (index + 1) / count;
  for (int64_t k = a; k < b; ++k) out.push_back(static_cast<int>(k));
  return out;
}

Status parse_batch_shard(const std::string& text, int* index, int* count) {
  const size_t slash = text.find('/');
  const auto bad = [&] {
    return Status::error(StatusCode::InvalidArgument,
                         "--shard expects i/n with 0 <= i < n (e.g. 0/4), got '" + io::quote_input(text, 40) + "'");
  };
  if (slash == std::string::npos) return bad();
  const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
  if (a.empty() || b.empty() || a.size() > 6 || b.size() > 6 ||
      a.find_first_not_of("0123456789") != std::string::npos || b.find_first_not_of("0123456789") != std::string::npos)
    return bad();
  *index = std::stoi(a);
  *count = std::stoi(b);
  if (*count < 1 || *index >= *count) return bad();
  return Status::success();
}

// ---- gather

BatchGatherResult gather_batch(const BatchManifest& m, const std::string& summary_path) {
  BatchGatherResult r;
  BatchSummary& out = r.summary;
  out.manifest = m.path;
  out.program = batch_program_version();
  out.jobs_total = static_cast<int>(m.jobs.size());
  out.warnings = m.warnings;
  // Shard summaries next to the summary: <stem>.shard-<i>-of-<n>.json.
  const fs::path sp(summary_path);
  const std::string prefix = without_json(sp.filename().string()) + ".shard-";
  const fs::path dir = sp.has_parent_path() ? sp.parent_path() : fs::path(".");
  std::map<int, std::string> shard_files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0 || name.size() < prefix.size() + 5 || name.compare(name.size() - 5, 5, ".json") != 0 ||
        name.find(".state.json") != std::string::npos)
      continue;
    int i = -1, n = 0;
    char tail[8] = {0};
    if (std::sscanf(name.c_str() + prefix.size(), "%d-of-%d%7s", &i, &n, tail) != 3 || std::string(tail) != ".json") continue;
    if (r.shards_expected == 0) r.shards_expected = n;
    if (n != r.shards_expected) {
      r.status = Status::error(StatusCode::InvalidArgument,
                               "shard summaries of different shard counts next to '" + io::quote_input(summary_path, 200) +
                                   "' (" + std::to_string(r.shards_expected) + " and " + std::to_string(n) +
                                   "); remove the old ones");
      return r;
    }
    shard_files[i] = entry.path().string();
  }
  if (shard_files.empty()) {
    r.status = Status::error(StatusCode::IoError, "no shard summaries '" + io::quote_input(prefix, 200) + "*-of-*.json' in '" +
                                                      io::quote_input(dir.string(), 200) + "'");
    return r;
  }
  std::vector<const BatchJobOutcome*> by_index(m.jobs.size(), nullptr);
  std::vector<BatchSummary> shards;
  shards.reserve(shard_files.size());
  BatchState merged_state;
  std::string state_warning;
  for (const auto& [i, path] : shard_files) {
    std::vector<uint8_t> bytes;
    if (!(r.status = io::read_file(path, &bytes)).ok()) return r;
    shards.emplace_back();
    BatchSummary& s = shards.back();
    if (Status st = parse_batch_summary(std::string(bytes.begin(), bytes.end()), &s); !st.ok()) {
      r.status = Status::error(st.code, io::quote_input(path, 200) + ": " + st.message);
      return r;
    }
    if (s.jobs_total != out.jobs_total) {
      r.status = Status::error(StatusCode::InvalidArgument, io::quote_input(path, 200) + " was made from a manifest with " +
                                                                std::to_string(s.jobs_total) + " jobs; this one has " +
                                                                std::to_string(out.jobs_total) + " (run the shards again)");
      return r;
    }
    ++r.shards_found;
    out.wall_ms = std::max(out.wall_ms, s.wall_ms);
    out.workers += s.workers;
    for (const BatchJobOutcome& o : s.jobs) {
      if (o.index < 0 || o.index >= out.jobs_total || o.id != m.jobs[static_cast<size_t>(o.index)].id ||
          by_index[static_cast<size_t>(o.index)]) {
        r.status = Status::error(StatusCode::InvalidArgument, io::quote_input(path, 200) + ": job " + std::to_string(o.index) +
                                                                  " does not match the manifest (or is in two shards)");
        return r;
      }
      by_index[static_cast<size_t>(o.index)] = &o;
    }
    const BatchState st = read_batch_state(batch_state_path(path), &state_warning);
    merged_state.insert(st.begin(), st.end());
  }
  for (size_t k = 0; k < m.jobs.size(); ++k) {
    if (by_index[k]) {
      out.jobs.push_back(*by_index[k]);
      continue;
    }
    BatchJobOutcome o;
    o.index = static_cast<int>(k);
    o.id = m.jobs[k].id;
    o.label = m.jobs[k].label;
    o.kind = batch_kind_name(m.jobs[k].kind);
    o.output = m.jobs[k].output;
    o.status = "not-run";
    o.message = "no shard summary holds this job (did every array task run?)";
    out.jobs.push_back(std::move(o));
  }
  // The whole batch's state, so that a later run of the manifest skips what the shards did.
  std::string w;
  BatchState state = read_batch_state(batch_state_path(summary_path), &w);
  for (auto& [id, e] : merged_state) state[id] = e;
  if (Status s = write_batch_state(batch_state_path(summary_path), state); !s.ok()) r.status = s;
  return r;
}

// ---- Slurm

namespace {
// Single-quoted for the shell.
std::string sh_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}
}  // namespace

SlurmScripts batch_slurm_scripts(const std::string& meshmorph, const std::string& manifest, const std::string& summary_path,
                                 const std::string& workdir, int shards, int cpus_per_task) {
  SlurmScripts s;
  const std::string logs = without_json(summary_path) + ".slurm-%A_%a.out";
  s.array_script = "#!/bin/bash\n"
                   "# One Slurm array task per shard of the batch (meshmorph batch --slurm; docs/batch.md).\n"
                   "#SBATCH --job-name=meshmorph-batch\n"
                   "#SBATCH --array=0-" + std::to_string(shards - 1) + "\n"
                   "#SBATCH --ntasks=1\n"
                   "#SBATCH --cpus-per-task=" + std::to_string(cpus_per_task) + "\n"
                   "#SBATCH --output=" + logs + "\n"
                   "set -eu\n"
                   "cd " + sh_quote(workdir) + "\n"
                   "exec " + sh_quote(meshmorph) + " batch " + sh_quote(manifest) + " --summary " + sh_quote(summary_path) +
                   " --shard \"${SLURM_ARRAY_TASK_ID}/" + std::to_string(shards) + "\" --jobs \"${SLURM_CPUS_PER_TASK:-" +
                   std::to_string(cpus_per_task) + "}\"\n";
  s.gather_script = "#!/bin/bash\n"
                    "# Merges the shard summaries of the array into one summary (runs after every task, failed or not).\n"
                    "#SBATCH --job-name=meshmorph-gather\n"
                    "#SBATCH --ntasks=1\n"
                    "#SBATCH --cpus-per-task=1\n"
                    "#SBATCH --output=" + without_json(summary_path) + ".slurm-gather-%j.out\n"
                    "set -eu\n"
                    "cd " + sh_quote(workdir) + "\n"
                    "exec " + sh_quote(meshmorph) + " batch " + sh_quote(manifest) + " --summary " + sh_quote(summary_path) +
                    " --gather\n";
  s.submit_script = "#!/bin/bash\n"
                    "# Submits the array and, after it (whatever its tasks' exit codes), the gather step.\n"
                    "set -eu\n"
                    "cd \"$(dirname \"$0\")\"\n"
                    "array=$(sbatch --parsable " + sh_quote(fs::path(without_json(summary_path) + ".slurm-array.sh").filename().string()) + ")\n"
                    "array=${array%%;*}\n"
                    "gather=$(sbatch --parsable --dependency=afterany:${array} " +
                    sh_quote(fs::path(without_json(summary_path) + ".slurm-gather.sh").filename().string()) + ")\n"
                    "echo \"submitted array job ${array} (" + std::to_string(shards) + " tasks) and gather job ${gather%%;*}\"\n";
  return s;
}

}  // namespace mm::app
