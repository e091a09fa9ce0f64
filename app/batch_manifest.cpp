#include "app/batch_manifest.h"

#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "app/edit_job.h"
#include "app/json_options.h"
#include "app/merge_job.h"
#include "app/retarget_job.h"
#include "app/transfer_job.h"
#include "io/asset.h"
#include "io/gltf_animation.h"
#include "io/json_text.h"

namespace mm::app {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const char* batch_kind_name(BatchKind k) {
  switch (k) {
    case BatchKind::Retarget: return "retarget";
    case BatchKind::Transfer: return "transfer";
    case BatchKind::Edit: return "edit";
    case BatchKind::Merge: return "merge";
  }
  return "?";
}

std::string batch_path_component(const std::string& value) {
  std::string out;
  for (char c : value) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                      c == '-' || c == '_';
    out += keep ? c : '_';
  }
  if (out.empty() || out == "." || out == "..") out = "_";
  return out;
}

Status list_source_clips(const std::string& source_path, std::vector<std::string>* clips) {
  const io::LoadResult lr = io::load_asset(source_path);
  if (!lr.status.ok()) return lr.status;
  const io::CharacterResult cr = io::animated_character(lr.asset);
  if (!cr.status.ok()) return cr.status;
  for (const AnimationClip& c : cr.character.clips) clips->push_back(c.name);
  if (clips->empty())
    return Status::error(StatusCode::InvalidArgument, "'" + io::quote_input(source_path, 200) + "' has no animation clips");
  return Status::success();
}

namespace {

// Everything the expansion of one manifest needs while it walks the groups.
struct Expander {
  BatchManifest* m = nullptr;
  const ClipLister* list_clips = nullptr;
  std::string default_output;
  Status st;

  bool fail(StatusCode code, const std::string& message) {
    st = Status::error(code, message);
    return false;
  }

  bool check_keys(const Json& obj, const std::set<std::string>& allowed, const std::string& where) {
    if (!obj.is_object()) return fail(StatusCode::ParseError, "manifest: " + where + " must be an object");
    for (auto it = obj.begin(); it != obj.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string known;
        for (const auto& a : allowed) known += (known.empty() ? "" : ", ") + a;
        return fail(StatusCode::ParseError, "manifest: unknown key \"" + io::quote_input(it.key(), 60) + "\" in " +
                                                where + " (keys: " + known + ")");
      }
    return true;
  }

  bool text(const Json& obj, const char* key, const std::string& where, std::string* out, bool required) {
    if (!obj.contains(key)) {
      if (required) return fail(StatusCode::ParseError, "manifest: " + where + " needs \"" + key + "\"");
      return true;
    }
    if (!obj[key].is_string() || obj[key].get<std::string>().empty())
      return fail(StatusCode::ParseError, "manifest: " + where + "." + key + " must be a non-empty string");
    *out = obj[key].get<std::string>();
    return true;
  }

  // A string or an array of strings (at least one).
  bool text_list(const Json& v, const std::string& where, std::vector<std::string>* out) {
    if (v.is_string()) {
      out->push_back(v.get<std::string>());
    } else if (v.is_array() && !v.empty()) {
      for (const Json& e : v) {
        if (!e.is_string()) return fail(StatusCode::ParseError, "manifest: " + where + " must hold strings");
        out->push_back(e.get<std::string>());
      }
    } else {
      return fail(StatusCode::ParseError, "manifest: " + where + " must be a string or a non-empty array of strings");
    }
    for (const auto& s : *out)
      if (s.empty()) return fail(StatusCode::ParseError, "manifest: " + where + " holds an empty string");
    return true;
  }

  std::string resolve(const std::string& p) const {
    const fs::path path(p);
    if (path.is_absolute() || m->dir.empty()) return path.lexically_normal().string();
    return (fs::path(m->dir) / path).lexically_normal().string();
  }

  // The group's options: validated through the job's schema now, kept as canonical JSON.
  template <class O>
  bool options(const Json& group, const OptionSchema<O>& schema, const std::string& where, std::string* out) {
    if (!group.contains("options")) {
      *out = "{}";
      return true;
    }
    const Json& o = group["options"];
    if (o.is_object() && schema.job() == "retarget" && o.contains("clip"))
      return fail(StatusCode::ParseError, "manifest: " + where + ".options: give clips with \"clips\", not the option \"clip\"");
    O probe;
    Status s = set_options_from_json(o, schema, &probe, "manifest: " + where);
    if (!s.ok()) {
      st = s;
      return false;
    }
    *out = o.dump();
    return true;
  }

  // Expands `pattern` with the placeholders of one job.
  bool output(const std::string& pattern, const std::map<std::string, std::string>& values, const std::string& where,
              std::string* out) {
    std::string r;
    for (size_t i = 0; i < pattern.size(); ++i) {
      if (pattern[i] == '}')
        return fail(StatusCode::ParseError, "manifest: " + where + ": output pattern \"" + io::quote_input(pattern, 120) +
                                                "\" has a '}' without '{'");
      if (pattern[i] != '{') {
        r += pattern[i];
        continue;
      }
      const size_t close = pattern.find('}', i);
      if (close == std::string::npos)
        return fail(StatusCode::ParseError, "manifest: " + where + ": output pattern \"" + io::quote_input(pattern, 120) +
                                                "\" has a '{' without '}'");
      const std::string name = pattern.substr(i + 1, close - i - 1);
      const auto it = values.find(name);
      if (it == values.end()) {
        std::string known;
        for (const auto& [k, v] : values) known += (known.empty() ? "{" : ", {") + k + "}";
        return fail(StatusCode::ParseError, "manifest: " + where + ": output pattern uses {" + io::quote_input(name, 40) +
                                                "}, which these jobs do not have (they have " + known +
                                                "; give the group its own \"output\")");
      }
      r += it->second;
      i = close;
    }
    *out = r;
    return true;
  }

  std::string pattern_of(const Json& group, const std::string& kind_default) const {
    if (group.contains("output") && group["output"].is_string()) return group["output"].get<std::string>();
    return default_output.empty() ? kind_default : default_output;
  }

  bool group_name(const Json& group, const std::string& where, std::map<std::string, std::string>* values) {
    std::string name;
    if (!text(group, "name", where, &name, false)) return false;
    if (!name.empty()) (*values)["name"] = batch_path_component(name);
    if (group.contains("output") && !group["output"].is_string())
      return fail(StatusCode::ParseError, "manifest: " + where + ".output must be a string");
    if (group.contains("comment") && !group["comment"].is_string())
      return fail(StatusCode::ParseError, "manifest: " + where + ".comment must be a string");
    return true;
  }

  void add(BatchJob job) {
    job.index = static_cast<int>(m->jobs.size());
    m->jobs.push_back(std::move(job));
  }

  static std::string stem(const std::string& path) { return batch_path_component(fs::path(path).stem().string()); }
  static std::string ext(const std::string& path) {
    const std::string e = fs::path(path).extension().string();
    return e.empty() ? "" : batch_path_component(e.substr(1));
  }

  bool retarget(const Json& g, const std::string& where) {
    if (!check_keys(g, {"sources", "source", "clips", "targets", "target", "options", "output", "name", "comment"}, where))
      return false;
    std::map<std::string, std::string> values{{"kind", "retarget"}, {"ext", "glb"}};
    if (!group_name(g, where, &values)) return false;
    std::vector<std::string> sources, targets_text;
    if (g.contains("sources") == g.contains("source"))
      return fail(StatusCode::ParseError, "manifest: " + where + " needs \"sources\" (or one \"source\")");
    if (!text_list(g.contains("sources") ? g["sources"] : g["source"], where + ".sources", &sources)) return false;
    if (g.contains("targets") == g.contains("target"))
      return fail(StatusCode::ParseError, "manifest: " + where + " needs \"targets\" (or one \"target\")");
    const Json& tj = g.contains("targets") ? g["targets"] : g["target"];
    struct Target {
      std::string path, joints, joint_map, name;
    };
    std::vector<Target> targets;
    const Json tlist = tj.is_array() ? tj : Json::array({tj});
    if (tlist.empty()) return fail(StatusCode::ParseError, "manifest: " + where + ".targets is empty");
    for (size_t i = 0; i < tlist.size(); ++i) {
      const std::string tw = where + ".targets[" + std::to_string(i) + "]";
      Target t;
      if (tlist[i].is_string()) {
        t.path = tlist[i].get<std::string>();
        if (t.path.empty()) return fail(StatusCode::ParseError, "manifest: " + tw + " is an empty string");
      } else {
        if (!check_keys(tlist[i], {"path", "joints", "joint_map", "name"}, tw)) return false;
        if (!text(tlist[i], "path", tw, &t.path, true) || !text(tlist[i], "joints", tw, &t.joints, false) ||
            !text(tlist[i], "joint_map", tw, &t.joint_map, false) || !text(tlist[i], "name", tw, &t.name, false))
          return false;
      }
      targets.push_back(t);
    }
    if (!g.contains("clips")) return fail(StatusCode::ParseError, "manifest: " + where + " needs \"clips\" (\"*\" for every clip)");
    std::vector<std::string> clips;
    if (!text_list(g["clips"], where + ".clips", &clips)) return false;
    const bool all_clips = clips.size() == 1 && clips[0] == "*";
    std::string opts;
    if (!options(g, retarget_options(), where, &opts)) return false;
    const std::string pattern = pattern_of(g, "out/retarget/{target}/{source}/{clip}.glb");
    for (const std::string& src_text : sources) {
      const std::string src = resolve(src_text);
      values["source"] = stem(src);
      std::vector<std::string> source_clips = clips;
      Status listing;
      if (all_clips) {
        source_clips.clear();
        std::vector<std::string> listed;
        listing = (*list_clips)(src, &listed);
        std::set<std::string> seen;
        for (const auto& c : listed) {
          if (seen.insert(c).second) source_clips.push_back(c);
          else
            m->warnings.push_back("'" + io::quote_input(src_text, 200) + "' has two clips named '" + io::quote_input(c, 80) +
                                  "'; only the first is retargeted");
        }
      }
      for (const Target& t : targets) {
        const std::string tgt = resolve(t.path);
        values["target"] = t.name.empty() ? stem(tgt) : batch_path_component(t.name);
        BatchJob base;
        base.kind = BatchKind::Retarget;
        base.files["source"] = src;
        base.files["target"] = tgt;
        if (!t.joints.empty()) base.files["target_joints"] = resolve(t.joints);
        if (!t.joint_map.empty()) base.files["joint_map"] = resolve(t.joint_map);
        base.options_json = opts;
        base.group = "retarget\n" + src + "\n" + tgt + "\n" + (t.joints.empty() ? "" : resolve(t.joints)) + "\n" +
                     (t.joint_map.empty() ? "" : resolve(t.joint_map)) + "\n" + opts;
        const std::string target_label = t.name.empty() ? fs::path(tgt).stem().string() : t.name;
        if (!listing.ok()) {
          BatchJob j = base;
          j.id = "retarget " + src_text + " clips \"*\" -> " + target_label;
          j.label = fs::path(src).stem().string() + "/* -> " + target_label;
          j.preflight = Status{listing.code, "cannot list the clips of '" + io::quote_input(src_text, 200) + "': " + listing.message};
          add(std::move(j));
          continue;
        }
        for (const std::string& clip : source_clips) {
          BatchJob j = base;
          j.clip = clip;
          values["clip"] = batch_path_component(clip);
          if (!output(pattern, values, where, &j.id)) return false;
          j.label = fs::path(src).stem().string() + "/" + clip + " -> " + target_label;
          add(std::move(j));
        }
      }
    }
    return true;
  }

  bool transfer(const Json& g, const std::string& where) {
    static const std::set<std::string> pair_keys{"reference", "source", "landmarks", "cage", "ground_truth"};
    std::set<std::string> keys{"pairs", "options", "output", "name", "comment"};
    keys.insert(pair_keys.begin(), pair_keys.end());
    if (!check_keys(g, keys, where)) return false;
    std::map<std::string, std::string> values{{"kind", "transfer"}};
    if (!group_name(g, where, &values)) return false;
    std::vector<std::pair<Json, std::string>> pairs;
    if (g.contains("pairs")) {
      if (!g["pairs"].is_array() || g["pairs"].empty())
        return fail(StatusCode::ParseError, "manifest: " + where + ".pairs must be a non-empty array");
      for (const std::string& k : pair_keys)
        if (g.contains(k))
          return fail(StatusCode::ParseError, "manifest: " + where + " has \"pairs\" and \"" + k + "\"; put it in each pair");
      for (size_t i = 0; i < g["pairs"].size(); ++i)
        pairs.emplace_back(g["pairs"][i], where + ".pairs[" + std::to_string(i) + "]");
    } else {
      Json one = Json::object();
      for (const std::string& k : pair_keys)
        if (g.contains(k)) one[k] = g[k];
      pairs.emplace_back(one, where);
    }
    std::string opts;
    if (!options(g, transfer_options(), where, &opts)) return false;
    const std::string pattern = pattern_of(g, "out/transfer/{source}-{reference}.{ext}");
    for (const auto& [p, pw] : pairs) {
      if (!check_keys(p, pair_keys, pw)) return false;
      BatchJob j;
      j.kind = BatchKind::Transfer;
      for (const char* role : {"reference", "source", "landmarks", "cage", "ground_truth"}) {
        std::string v;
        if (!text(p, role, pw, &v, std::string(role) == "reference" || std::string(role) == "source")) return false;
        if (!v.empty()) j.files[role] = resolve(v);
      }
      values["source"] = stem(j.files["source"]);
      values["reference"] = stem(j.files["reference"]);
      values["ext"] = ext(j.files["source"]);
      j.options_json = opts;
      if (!output(pattern, values, pw, &j.id)) return false;
      j.label = fs::path(j.files["source"]).stem().string() + " as " + fs::path(j.files["reference"]).stem().string();
      add(std::move(j));
    }
    return true;
  }

  bool edit(const Json& g, const std::string& where) {
    if (!check_keys(g, {"input", "spec", "specs", "options", "output", "name", "comment"}, where)) return false;
    std::map<std::string, std::string> values{{"kind", "edit"}};
    if (!group_name(g, where, &values)) return false;
    std::string input;
    if (!text(g, "input", where, &input, true)) return false;
    if (g.contains("specs") == g.contains("spec"))
      return fail(StatusCode::ParseError, "manifest: " + where + " needs \"specs\" (or one \"spec\")");
    std::vector<std::string> specs;
    if (!text_list(g.contains("specs") ? g["specs"] : g["spec"], where + ".specs", &specs)) return false;
    std::string opts;
    if (!options(g, edit_options(), where, &opts)) return false;
    const std::string pattern = pattern_of(g, "out/edit/{input}-{spec}.{ext}");
    const std::string in = resolve(input);
    values["input"] = stem(in);
    values["ext"] = ext(in);
    for (const std::string& s : specs) {
      BatchJob j;
      j.kind = BatchKind::Edit;
      j.files["input"] = in;
      j.files["spec"] = resolve(s);
      values["spec"] = stem(j.files["spec"]);
      j.options_json = opts;
      if (!output(pattern, values, where, &j.id)) return false;
      j.label = fs::path(in).stem().string() + " by " + fs::path(j.files["spec"]).stem().string();
      add(std::move(j));
    }
    return true;
  }

  bool merge(const Json& g, const std::string& where) {
    if (!check_keys(g, {"target", "source", "spec", "options", "output", "name", "comment"}, where)) return false;
    std::map<std::string, std::string> values{{"kind", "merge"}};
    if (!group_name(g, where, &values)) return false;
    BatchJob j;
    j.kind = BatchKind::Merge;
    for (const char* role : {"target", "source", "spec"}) {
      std::string v;
      if (!text(g, role, where, &v, true)) return false;
      j.files[role] = resolve(v);
      values[role] = stem(j.files[role]);
    }
    values["ext"] = ext(j.files["target"]);
    if (!options(g, merge_options(), where, &j.options_json)) return false;
    if (!output(pattern_of(g, "out/merge/{target}-{source}.{ext}"), values, where, &j.id)) return false;
    j.label = fs::path(j.files["source"]).stem().string() + " onto " + fs::path(j.files["target"]).stem().string();
    add(std::move(j));
    return true;
  }
};

}  // namespace

BatchManifestResult parse_batch_manifest(const std::string& text, const std::string& manifest_path,
                                         const ClipLister& list_clips) {
  BatchManifestResult out;
  BatchManifest& m = out.manifest;
  m.path = manifest_path;
  std::error_code ec;
  const fs::path absolute = fs::absolute(fs::path(manifest_path), ec);
  m.dir = (ec ? fs::path(manifest_path) : absolute).parent_path().lexically_normal().string();
  if (Status d = io::check_json_depth(text, "manifest"); !d.ok()) {
    out.status = d;
    return out;
  }
  const Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    out.status = Status::error(StatusCode::ParseError, "manifest '" + io::quote_input(manifest_path, 200) + "' is not valid JSON");
    return out;
  }
  Expander e;
  e.m = &m;
  e.list_clips = &list_clips;
  try {
    if (!e.check_keys(j, {"output", "summary", "retarget", "transfer", "edit", "merge", "comment"}, "the manifest")) {
      out.status = e.st;
      return out;
    }
    std::string summary;
    if (!e.text(j, "output", "the manifest", &e.default_output, false) ||
        !e.text(j, "summary", "the manifest", &summary, false)) {
      out.status = e.st;
      return out;
    }
    if (summary.empty()) summary = fs::path(manifest_path).stem().string() + ".summary.json";
    m.summary_path = e.resolve(summary);
    if (m.summary_path.size() < 6 || m.summary_path.substr(m.summary_path.size() - 5) != ".json") {
      out.status = Status::error(StatusCode::ParseError, "manifest: \"summary\" must name a .json file");
      return out;
    }
    const std::pair<const char*, bool (Expander::*)(const Json&, const std::string&)> kinds[] = {
        {"retarget", &Expander::retarget}, {"transfer", &Expander::transfer}, {"edit", &Expander::edit}, {"merge", &Expander::merge}};
    bool any = false;
    for (const auto& [key, fn] : kinds) {
      if (!j.contains(key)) continue;
      const Json& groups = j[key];
      if (!groups.is_array()) {
        out.status = Status::error(StatusCode::ParseError, std::string("manifest: \"") + key + "\" must be an array of job groups");
        return out;
      }
      for (size_t i = 0; i < groups.size(); ++i) {
        if (!(e.*fn)(groups[i], std::string(key) + "[" + std::to_string(i) + "]")) {
          out.status = e.st;
          return out;
        }
        any = true;
      }
    }
    if (!any) {
      out.status = Status::error(StatusCode::ParseError, "manifest: no jobs (give \"retarget\", \"transfer\", \"edit\" or \"merge\")");
      return out;
    }
  } catch (const std::exception& ex) {
    out.status = Status::error(StatusCode::ParseError, io::cap_message(std::string("manifest: ") + ex.what()));
    return out;
  }

  // Outputs: resolved, unique, never an input, with a format the job can write.
  std::map<std::string, const BatchJob*> by_output;
  std::set<std::string> inputs;
  for (const BatchJob& job : m.jobs)
    for (const auto& [role, path] : job.files) inputs.insert(path);
  for (BatchJob& job : m.jobs) {
    if (!job.preflight.ok()) continue;
    job.output = e.resolve(job.id);
    const auto fmt = io::format_from_path(job.output);
    if (job.kind == BatchKind::Retarget ? fs::path(job.output).extension() != ".glb" : !fmt) {
      out.status = Status::error(StatusCode::ParseError,
                                 "manifest: output '" + io::quote_input(job.id, 200) + "' of " + job.label + ": " +
                                     (job.kind == BatchKind::Retarget ? "retarget outputs are .glb files"
                                                                      : "unknown format (.glb, .gltf, .obj, .off, .ply)"));
      return out;
    }
    if (inputs.count(job.output)) {
      out.status = Status::error(StatusCode::ParseError, "manifest: output '" + io::quote_input(job.id, 200) + "' of " +
                                                             job.label + " is an input of the batch");
      return out;
    }
    const auto [it, fresh] = by_output.emplace(job.output, &job);
    if (!fresh) {
      out.status = Status::error(StatusCode::ParseError, "manifest: " + it->second->label + " and " + job.label +
                                                             " both write '" + io::quote_input(job.id, 200) +
                                                             "' (add {clip}, {target}, ... to the output pattern)");
      return out;
    }
  }
  return out;
}

BatchManifestResult load_batch_manifest(const std::string& manifest_path, const ClipLister& list_clips) {
  std::vector<uint8_t> bytes;
  BatchManifestResult out;
  if (!(out.status = io::read_file(manifest_path, &bytes)).ok()) return out;
  return parse_batch_manifest(std::string(bytes.begin(), bytes.end()), manifest_path, list_clips);
}

}  // namespace mm::app
