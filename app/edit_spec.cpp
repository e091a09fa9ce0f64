#include "app/edit_spec.h"

#include <cmath>
#include <cstdint>
#include <set>

#include <nlohmann/json.hpp>

#include "app/edit_job.h"
#include "app/json_options.h"
#include "edit/selection.h"
#include "io/json_text.h"
#include "mesh/mesh.h"

namespace mm {

namespace edit_spec_detail {

using EditSpecJson = nlohmann::json;

// Parsing context: the first error wins; every accessor checks types so nlohmann never throws.
struct EditSpecParser {
  const Eigen::MatrixXd& V;
  const Eigen::MatrixXi& F;
  double diag = 1;
  Status status;

  bool fail(StatusCode code, const std::string& msg) {
    if (status.ok()) status = Status::error(code, msg);
    return false;
  }
  bool check_keys(const EditSpecJson& obj, const std::set<std::string>& allowed, const std::string& where) {
    for (auto it = obj.begin(); it != obj.end(); ++it)
      if (!allowed.count(it.key())) return fail(StatusCode::ParseError, "unknown key \"" + io::quote_input(it.key(), 60) + "\" in " + where);
    return true;
  }
  bool number(const EditSpecJson& j, const std::string& where, double* out) {
    if (!j.is_number()) return fail(StatusCode::ParseError, where + " must be a number");
    *out = j.get<double>();
    if (!std::isfinite(*out)) return fail(StatusCode::InvalidArgument, where + " must be finite");
    return true;
  }
  bool integer(const EditSpecJson& j, const std::string& where, int* out) {
    if (!j.is_number_integer()) return fail(StatusCode::ParseError, where + " must be an integer");
    // get<int> of a larger value would wrap (4294967296 → vertex 0): out of range instead.
    const bool fits = j.is_number_unsigned() ? j.get<uint64_t>() <= uint64_t{INT32_MAX}
                                             : j.get<int64_t>() >= INT32_MIN && j.get<int64_t>() <= INT32_MAX;
    if (!fits) return fail(StatusCode::InvalidArgument, where + " = " + j.dump() + " is out of range");
    *out = j.get<int>();
    return true;
  }
  bool vec3(const EditSpecJson& j, const std::string& where, Eigen::Vector3d* out) {
    if (!j.is_array() || j.size() != 3) return fail(StatusCode::ParseError, where + " must be an array of 3 numbers");
    for (int k = 0; k < 3; ++k)
      if (!number(j[k], where + "[" + std::to_string(k) + "]", &(*out)[k])) return false;
    return true;
  }
  // "name" (mesh units) or "name_rel" (× bbox diagonal); `found` tells whether either was given.
  bool length(const EditSpecJson& obj, const std::string& name, const std::string& where, double* out, bool* found) {
    *found = false;
    if (obj.contains(name)) {
      *found = true;
      return number(obj[name], where + "." + name, out);
    }
    if (obj.contains(name + "_rel")) {
      *found = true;
      if (!number(obj[name + "_rel"], where + "." + name + "_rel", out)) return false;
      *out *= diag;
    }
    return true;
  }

  bool selection(const EditSpecJson& j, const std::string& where, std::vector<int>* out) {
    VertexSelection sel;
    if (j.is_array()) {
      for (size_t k = 0; k < j.size(); ++k) {
        int v;
        if (!integer(j[k], where + "[" + std::to_string(k) + "]", &v)) return false;
        sel.indices.push_back(v);
      }
    } else if (j.is_object()) {
      if (!check_keys(j, {"indices", "spheres", "boxes", "rings", "disks", "slabs"}, where)) return false;
      auto list = [&](const char* key) -> const EditSpecJson* {
        if (!j.contains(key)) return nullptr;
        if (!j[key].is_array()) {
          fail(StatusCode::ParseError, where + "." + key + " must be an array");
          return nullptr;
        }
        return &j[key];
      };
      if (j.contains("indices") && !selection(j["indices"], where + ".indices", &sel.indices)) return false;
      if (const EditSpecJson* a = list("spheres"))
        for (size_t k = 0; k < a->size(); ++k) {
          const EditSpecJson& e = (*a)[k];
          const std::string w = where + ".spheres[" + std::to_string(k) + "]";
          if (!e.is_object() || !check_keys(e, {"center", "vertex", "radius", "radius_rel"}, w))
            return fail(StatusCode::ParseError, w + " must be an object with center|vertex and radius|radius_rel");
          VertexSelection::Sphere s;
          bool found = false;
          if (!length(e, "radius", w, &s.radius, &found)) return false;
          if (!found) return fail(StatusCode::ParseError, w + " needs radius or radius_rel");
          if (e.contains("center")) {
            if (!vec3(e["center"], w + ".center", &s.center)) return false;
          } else if (e.contains("vertex")) {
            int v;
            if (!integer(e["vertex"], w + ".vertex", &v)) return false;
            if (v < 0 || v >= V.rows())
              return fail(StatusCode::InvalidArgument, w + ".vertex " + std::to_string(v) + " is out of range (mesh has " +
                                                           std::to_string(V.rows()) + " vertices)");
            s.center = V.row(v).transpose();
          } else {
            return fail(StatusCode::ParseError, w + " needs center or vertex");
          }
          sel.spheres.push_back(s);
        }
      if (const EditSpecJson* a = list("boxes"))
        for (size_t k = 0; k < a->size(); ++k) {
          const EditSpecJson& e = (*a)[k];
          const std::string w = where + ".boxes[" + std::to_string(k) + "]";
          if (!e.is_object() || !check_keys(e, {"min", "max"}, w)) return fail(StatusCode::ParseError, w + " must be {min, max}");
          VertexSelection::Box b;
          if (!e.contains("min") || !e.contains("max")) return fail(StatusCode::ParseError, w + " needs min and max");
          if (!vec3(e["min"], w + ".min", &b.min) || !vec3(e["max"], w + ".max", &b.max)) return false;
          sel.boxes.push_back(b);
        }
      if (const EditSpecJson* a = list("rings"))
        for (size_t k = 0; k < a->size(); ++k) {
          const EditSpecJson& e = (*a)[k];
          const std::string w = where + ".rings[" + std::to_string(k) + "]";
          if (!e.is_object() || !check_keys(e, {"vertex", "k"}, w) || !e.contains("vertex"))
            return fail(StatusCode::ParseError, w + " must be {vertex, k}");
          VertexSelection::Ring r;
          if (!integer(e["vertex"], w + ".vertex", &r.vertex)) return false;
          if (e.contains("k") && !integer(e["k"], w + ".k", &r.k)) return false;
          sel.rings.push_back(r);
        }
      if (const EditSpecJson* a = list("disks"))
        for (size_t k = 0; k < a->size(); ++k) {
          const EditSpecJson& e = (*a)[k];
          const std::string w = where + ".disks[" + std::to_string(k) + "]";
          if (!e.is_object() || !check_keys(e, {"vertex", "radius", "radius_rel"}, w) || !e.contains("vertex"))
            return fail(StatusCode::ParseError, w + " must be {vertex, radius|radius_rel}");
          VertexSelection::GeodesicDisk d;
          if (!integer(e["vertex"], w + ".vertex", &d.vertex)) return false;
          bool found = false;
          if (!length(e, "radius", w, &d.radius, &found)) return false;
          if (!found) return fail(StatusCode::ParseError, w + " needs radius or radius_rel");
          sel.disks.push_back(d);
        }
      if (const EditSpecJson* a = list("slabs"))
        for (size_t k = 0; k < a->size(); ++k) {
          const EditSpecJson& e = (*a)[k];
          const std::string w = where + ".slabs[" + std::to_string(k) + "]";
          if (!e.is_object() || !check_keys(e, {"axis", "from", "to"}, w))
            return fail(StatusCode::ParseError, w + " must be {axis, from, to}");
          VertexSelection::Slab s;
          if (e.contains("axis")) {
            if (!e["axis"].is_string()) return fail(StatusCode::ParseError, w + ".axis must be \"x\", \"y\", \"z\" or \"long\"");
            const std::string a2 = e["axis"].get<std::string>();
            s.axis = a2 == "x" ? 0 : a2 == "y" ? 1 : a2 == "z" ? 2 : a2 == "long" ? -1 : -2;
            if (s.axis == -2) return fail(StatusCode::ParseError, w + ".axis must be \"x\", \"y\", \"z\" or \"long\"");
          }
          if (e.contains("from") && !number(e["from"], w + ".from", &s.from)) return false;
          if (e.contains("to") && !number(e["to"], w + ".to", &s.to)) return false;
          sel.slabs.push_back(s);
        }
    } else {
      return fail(StatusCode::ParseError, where + " must be an array of vertex indices or a selector object");
    }
    SelectionResult r = select_vertices(V, F, sel);
    if (!r.status.ok()) return fail(r.status.code, where + ": " + r.status.message);
    *out = std::move(r.vertices);
    return true;
  }

  bool transform(const EditSpecJson& j, const std::string& where, const std::vector<int>& handle, HandleTransform* out) {
    if (j.contains("matrix")) {
      const EditSpecJson& m = j["matrix"];
      if (!m.is_array() || m.size() != 16)
        return fail(StatusCode::ParseError, where + ".matrix must be 16 numbers (column-major 4x4)");
      double a[16];
      for (int k = 0; k < 16; ++k)
        if (!number(m[k], where + ".matrix[" + std::to_string(k) + "]", &a[k])) return false;
      if (a[3] != 0 || a[7] != 0 || a[11] != 0 || a[15] != 1)
        return fail(StatusCode::InvalidArgument, where + ".matrix must be affine (last row 0 0 0 1)");
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) out->linear(r, c) = a[4 * c + r];
        out->translation[r] = a[12 + r];
      }
      return true;
    }
    Eigen::Vector3d t = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::Zero();
    double angle = 0, scale = 1;
    if (j.contains("translate") && !vec3(j["translate"], where + ".translate", &t)) return false;
    if (j.contains("translate_rel")) {
      if (!vec3(j["translate_rel"], where + ".translate_rel", &t)) return false;
      t *= diag;
    }
    if (j.contains("rotate")) {
      const EditSpecJson& r = j["rotate"];
      const std::string w = where + ".rotate";
      if (!r.is_object() || !check_keys(r, {"axis", "degrees", "radians"}, w))
        return fail(StatusCode::ParseError, w + " must be {axis, degrees|radians}");
      if (!r.contains("axis") || !vec3(r["axis"], w + ".axis", &axis)) return fail(StatusCode::ParseError, w + " needs an axis");
      if (!(axis.norm() > 0)) return fail(StatusCode::InvalidArgument, w + ".axis must not be zero");
      if (r.contains("degrees")) {
        if (!number(r["degrees"], w + ".degrees", &angle)) return false;
        angle *= M_PI / 180.0;
      } else if (r.contains("radians")) {
        if (!number(r["radians"], w + ".radians", &angle)) return false;
      }
    }
    if (j.contains("scale")) {
      if (!number(j["scale"], where + ".scale", &scale)) return false;
      if (!(scale > 0)) return fail(StatusCode::InvalidArgument, where + ".scale must be > 0");
    }
    Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
    if (j.contains("pivot") && !j["pivot"].is_string()) {
      if (!vec3(j["pivot"], where + ".pivot", &pivot)) return false;
    } else {
      if (j.contains("pivot") && j["pivot"].get<std::string>() != "centroid")
        return fail(StatusCode::ParseError, where + ".pivot must be [x,y,z] or \"centroid\"");
      for (int v : handle) pivot += V.row(v).transpose();
      if (!handle.empty()) pivot /= static_cast<double>(handle.size());
    }
    *out = HandleTransform::similarity(t, axis, angle, pivot, scale);
    return true;
  }
};

const std::set<std::string>& edit_spec_transform_keys() {
  static const std::set<std::string> k = {"translate", "translate_rel", "rotate", "pivot", "scale", "matrix"};
  return k;
}

}  // namespace edit_spec_detail

using namespace edit_spec_detail;

EditSpecResult parse_edit_spec(const std::string& json_text, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  EditSpecResult out;
  if (Status d = io::check_json_depth(json_text, "edit spec"); !d.ok()) {
    out.status = d;
    return out;
  }
  EditSpecParser p{V, F, bounding_box_diagonal(V), {}};
  const EditSpecJson j = EditSpecJson::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    out.status = Status::error(StatusCode::ParseError, "edit spec is not valid JSON");
    return out;
  }
  try {
    if (!j.is_object()) {
      out.status = Status::error(StatusCode::ParseError, "edit spec must be a JSON object");
      return out;
    }
    EditSpec& spec = out.spec;
    if (!p.check_keys(j, {"roi", "fixed", "handles", "features", "options", "comment"}, "the edit spec")) {
      out.status = p.status;
      return out;
    }
    if (j.contains("roi") && !p.selection(j["roi"], "roi", &spec.region.roi)) {
      out.status = p.status;
      return out;
    }
    if (j.contains("roi") && spec.region.roi.empty()) {
      out.status = Status::error(StatusCode::InvalidArgument, "roi selects no vertex");
      return out;
    }
    if (j.contains("fixed") && !p.selection(j["fixed"], "fixed", &spec.region.fixed)) {
      out.status = p.status;
      return out;
    }
    if (!j.contains("handles") || !j["handles"].is_array() || j["handles"].empty()) {
      out.status = Status::error(StatusCode::InvalidArgument, "the edit spec needs a non-empty \"handles\" array");
      return out;
    }
    const EditSpecJson& hs = j["handles"];
    for (size_t h = 0; h < hs.size(); ++h) {
      const std::string w = "handles[" + std::to_string(h) + "]";
      std::set<std::string> keys = edit_spec_transform_keys();
      keys.insert({"select", "name"});
      if (!hs[h].is_object() || !p.check_keys(hs[h], keys, w) || !hs[h].contains("select")) {
        out.status = p.status.ok() ? Status::error(StatusCode::ParseError, w + " must be an object with \"select\"") : p.status;
        return out;
      }
      std::vector<int> handle;
      if (!p.selection(hs[h]["select"], w + ".select", &handle)) {
        out.status = p.status;
        return out;
      }
      if (handle.empty()) {
        out.status = Status::error(StatusCode::InvalidArgument, w + ".select selects no vertex");
        return out;
      }
      HandleTransform t;
      if (!p.transform(hs[h], w, handle, &t)) {
        out.status = p.status;
        return out;
      }
      spec.region.handles.push_back(std::move(handle));
      spec.transforms.push_back(t);
    }
    if (j.contains("features")) {
      const EditSpecJson& f = j["features"];
      if (!f.is_string() || (f.get<std::string>() != "keep" && f.get<std::string>() != "scale")) {
        out.status = Status::error(StatusCode::ParseError, "features must be \"keep\" or \"scale\"");
        return out;
      }
      spec.features = f.get<std::string>() == "scale" ? FeatureSize::Scale : FeatureSize::Keep;
    }
    if (j.contains("options")) {
      // Every key is an edit option of the job's schema (app/edit_job.h), as in the CLI and the page.
      app::EditJobOptions jo{spec.options, spec.features};
      if (const Status s = app::set_options_from_json(j["options"], app::edit_options(), &jo, "edit spec"); !s.ok()) {
        out.status = s;
        return out;
      }
      spec.options = jo.editor;
      spec.features = jo.features;
    }
  } catch (const std::exception& e) {
    // The accessors above check types; this is a last line so that nothing escapes the API.
    out.status = Status::error(StatusCode::ParseError, std::string("edit spec: ") + e.what());
  }
  return out;
}

HandleTransformsResult parse_handle_transforms(const std::string& json_text, const Eigen::MatrixXd& V,
                                               const EditRegion& region) {
  HandleTransformsResult out;
  Eigen::MatrixXi noF(0, 3);
  if (Status d = io::check_json_depth(json_text, "handle transforms"); !d.ok()) {
    out.status = d;
    return out;
  }
  EditSpecParser p{V, noF, bounding_box_diagonal(V), {}};
  const EditSpecJson j = EditSpecJson::parse(json_text, nullptr, false);
  if (j.is_discarded() || !j.is_array()) {
    out.status = Status::error(StatusCode::ParseError, "handle transforms must be a JSON array (one object per handle)");
    return out;
  }
  if (j.size() != region.handles.size()) {
    out.status = Status::error(StatusCode::InvalidArgument, "got " + std::to_string(j.size()) + " handle transforms for " +
                                                                std::to_string(region.handles.size()) + " handles");
    return out;
  }
  try {
    for (size_t h = 0; h < j.size(); ++h) {
      const std::string w = "transform[" + std::to_string(h) + "]";
      HandleTransform t;
      if (!j[h].is_object() || !p.check_keys(j[h], edit_spec_transform_keys(), w) || !p.transform(j[h], w, region.handles[h], &t)) {
        out.status = p.status.ok() ? Status::error(StatusCode::ParseError, w + " must be an object") : p.status;
        return out;
      }
      out.transforms.push_back(t);
    }
  } catch (const std::exception& e) {
    out.status = Status::error(StatusCode::ParseError, std::string("handle transforms: ") + e.what());
  }
  return out;
}

}  // namespace mm
