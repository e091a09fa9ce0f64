#include "app/joints_job.h"

#include <cstdio>

#include "io/gltf_document.h"
#include "io/joints_json.h"

namespace mm::app {

const OptionSchema<JointsJobOptions>& joints_options() {
  using O = JointsJobOptions;
  static const OptionSchema<O> schema = [] {
    OptionSchema<O> s("joints", "automatic joints: fit a source character's skeleton inside an unrigged target");
    s.integer("resolution", [](O& o) -> int& { return o.fit.skeleton.resolution; }, 16, 512,
              "voxel cells along the longest side for the curve skeleton");
    s.number("band_width", [](O& o) -> double& { return o.fit.skeleton.band_width; }, 1.7320508, 64,
             "geodesic band width of the level-set skeleton, in cells");
    s.integer("close_holes", [](O& o) -> int& { return o.fit.skeleton.close_holes; }, 0, 8,
              "holes up to about twice this many cells are closed before filling the volume");
    s.number("prune_length", [](O& o) -> double& { return o.fit.skeleton.prune_length; }, 0, 1,
             "skeleton branches shorter than this × the longest side are removed");
    s.choice<SourceSkeleton>("source_skeleton", [](O& o) -> SourceSkeleton& { return o.fit.source_skeleton; },
                             {{"auto", SourceSkeleton::Auto}, {"voxel", SourceSkeleton::Voxel}, {"bones", SourceSkeleton::Bones}},
                             "the source's tree: its curve skeleton (voxel), its own bones with tips at the surface (bones: for blocky, many-part sources), or voxel and bones where a source limb finds no partner (auto)");
    s.integer("source_up", [](O& o) -> int& { return o.fit.source_up; }, 0, 5,
              "source up axis: 0..2 = +x,+y,+z, 3..5 = -x,-y,-z (glTF: 1)");
    s.integer("target_up", [](O& o) -> int& { return o.fit.target_up; }, -1, 5,
              "target up axis as source_up; -1 = +y for glTF, else detect (the end with most feet)");
    s.integer("target_front", [](O& o) -> int& { return o.fit.target_front; }, -1, 5,
              "target facing axis as source_up; -1 = +z for glTF, else detect");
    s.number("leaf_tolerance", [](O& o) -> double& { return o.fit.leaf_tolerance; }, 0, 10,
             "limb ends match when at most this × height apart");
    s.boolean("match_by_attachment", [](O& o) -> bool& { return o.fit.match_by_attachment; },
              "source limbs posed unlike the target's (hanging arms against a T-pose) pair with its unmatched limbs by where they join the body");
    s.integer("surface_refine", [](O& o) -> int& { return o.fit.surface_refine_iterations; }, 0, 10,
              "rounds of moving each joint by the local affine map of the source surface around it onto the target (0 = off)");
    s.number("surface_refine_sigma", [](O& o) -> double& { return o.fit.surface_refine_sigma; }, 0.1, 10,
             "that neighbourhood: Gaussian sigma = this x the joint's depth below the source surface");
    s.boolean("surface_refine_seen", [](O& o) -> bool& { return o.fit.surface_refine_seen; },
              "the surface around a joint is only what the joint sees through the source's solid (not a neighbouring limb across empty space)");
    s.number("skeleton_prior", [](O& o) -> double& { return o.fit.skeleton_prior; }, 0, 100,
             "weight of the source's bones (scaled to the target) against the fitted joints, for a target of the source's rig family (0 = off)");
    s.number("skeleton_prior_agreement", [](O& o) -> double& { return o.fit.skeleton_prior_agreement; }, 0, 10,
             "the prior is used in full while the fitted bones differ from the source's by at most this (relative), and not at all beyond 1.6 x this");
    s.number("offset_cap", [](O& o) -> double& { return o.fit.offset_cap; }, 0, 100,
             "outside the source's rig family, a joint's offset from its skeleton point is at most this x the skeleton's radius there (0 = off)");
    s.number("ball_joint_reach", [](O& o) -> double& { return o.fit.ball_joint_reach; }, 0, 100,
             "a target built of parts bends at its small round parts: a fitted joint within this x such a ball's radius of its centre moves there (0 = off)");
    s.number("mirror_symmetry", [](O& o) -> double& { return o.fit.mirror_symmetry; }, 0, 1,
             "a target that is its own mirror image to within this x its height (mean) gets mirror-image joint pairs (0 = off)");
    s.number("depth_span_ratio", [](O& o) -> double& { return o.fit.depth_span_ratio; }, 0, 100,
             "a joint across a limb moves to its source joint's fraction of the limb's front-to-back depth where the two depths are within this ratio (<= 1 = off)");
    s.number("middle_span_ratio", [](O& o) -> double& { return o.fit.middle_span_ratio; }, 0, 100,
             "a joint on the source's middle plane where limbs branch off to both sides moves sideways to the middle of the target's section plus its source joint's offset, where the two widths are within this ratio (<= 1 = off)");
    s.integer("marker_reach", [](O& o) -> int& { return o.fit.marker_reach; }, 0, 100,
              "markers also move joints up to this many bones away");
    s.number("marker_anchor", [](O& o) -> double& { return o.fit.marker_anchor; }, 0, 1,
             "a marker within this x height of the target's skeleton path re-anchors the proportions along it (0 = off)");
    s.boolean("check_topology", [](O& o) -> bool& { return o.fit.check_topology; },
              "refuse a source of another kind (biped vs quadruped)");
    s.choice<io::SurfaceSelection>("surface", [](O& o) -> io::SurfaceSelection& { return o.surface; },
                                   {{"auto", io::SurfaceSelection::Auto}, {"skinned", io::SurfaceSelection::SkinnedOnly},
                                    {"all", io::SurfaceSelection::All}},
                                   "which glTF primitives form each character");
    return s;
  }();
  return schema;
}

std::string joints_json_text(const JointSet& joints) {
  std::string s = "{\n";
  for (int j = 0; j < joints.size(); ++j) {
    char buf[128];
    // 17 digits: the file reads back to the same doubles, so a retargeting from it (the page's
    // fit, `--target-joints J.json`) equals one that fitted the joints itself (`--target-joints
    // auto`). With 9 the Fox's clip on wolf0 with a pinned head differed by 1.4e-3 of the height.
    std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", joints.P(j, 0), joints.P(j, 1), joints.P(j, 2));
    std::string name;
    for (char c : joints.names[j]) {
      if (c == '"' || c == '\\') name += '\\';
      if (static_cast<unsigned char>(c) < 0x20) continue;
      name += c;
    }
    s += "  \"" + name + "\": " + buf + (j + 1 < joints.size() ? ",\n" : "\n");
  }
  return s + "}\n";
}

JointsJobResult run_joints_job(const io::Asset& source, const io::Asset& target, const std::string& markers_json,
                               const JointsJobOptions& opt, const Progress& progress) {
  JointsJobResult r;
  io::CharacterOptions co;
  co.surface = opt.surface;
  io::CharacterResult src = io::animated_character(source, co);
  if (!src.status.ok()) return r.status = Status{src.status.code, "source: " + src.status.message}, r;
  for (auto& w : src.warnings) r.warnings.push_back("source: " + w);
  if (src.character.main_skin < 0)
    return r.status = Status::error(StatusCode::InvalidArgument,
                                    "the source '" + source.source_name + "' has no skin: its joints are what is fitted"),
           r;
  if (io::gltf_model(target) != nullptr) {
    io::CharacterResult tr = io::animated_character(target, co);
    if (!tr.status.ok()) return r.status = Status{tr.status.code, "target: " + tr.status.message}, r;
    for (auto& w : tr.warnings) r.warnings.push_back("target: " + w);
    r.target_V = tr.character.V_rest;
    r.target_F = tr.character.F;
  } else {
    r.target_V = target.V_raw;
    r.target_F = target.F_raw;
  }
  std::vector<JointMarker> markers;
  if (!markers_json.empty()) {
    io::JointSetResult mr = io::parse_joints_json(markers_json);
    if (!mr.status.ok()) return r.status = Status{mr.status.code, "markers: " + mr.status.message}, r;
    for (int i = 0; i < mr.joints.size(); ++i) markers.push_back({mr.joints.names[i], mr.joints.P.row(i).transpose()});
  }
  JointFitOptions fo = opt.fit;
  if (io::gltf_model(target) != nullptr) {  // glTF: +Y up, front +Z by its spec
    if (fo.target_up < 0) fo.target_up = 1;
    if (fo.target_front < 0 && fo.target_up % 3 != 2) fo.target_front = 2;
  }
  r.fit = fit_joints(src.character.V_rest, src.character.F, character_joints(src.character), r.target_V, r.target_F,
                     markers, fo, progress);
  if (!r.fit.status.ok()) return r.status = r.fit.status, r;
  for (auto& w : r.fit.warnings) r.warnings.push_back(w);
  r.json = joints_json_text(r.fit.joints);
  return r;
}

}  // namespace mm::app
