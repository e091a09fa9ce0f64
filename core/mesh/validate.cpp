#include "mesh/validate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <sstream>

#include <Eigen/Geometry>

#include "mesh/topology.h"

namespace mm {

const char* mesh_defect_name(MeshDefect d) {
  switch (d) {
    case MeshDefect::Empty: return "empty mesh";
    case MeshDefect::NonFiniteCoordinate: return "non-finite (NaN/Inf) coordinates";
    case MeshDefect::IndexOutOfRange: return "out-of-range face indices";
    case MeshDefect::DegenerateFace: return "degenerate faces";
    case MeshDefect::DuplicateFace: return "duplicate faces";
    case MeshDefect::NonManifoldEdge: return "non-manifold edges";
    case MeshDefect::NonManifoldVertex: return "non-manifold vertices";
    case MeshDefect::UnreferencedVertex: return "unreferenced vertices";
    case MeshDefect::InconsistentOrientation: return "inconsistently oriented edges";
  }
  return "unknown defect";
}

int MeshReport::count(MeshDefect d) const {
  for (const auto& r : defects)
    if (r.defect == d) return r.count;
  return 0;
}

Status MeshReport::status(const std::vector<MeshDefect>& fatal) const {
  for (const auto& r : defects) {
    if (std::find(fatal.begin(), fatal.end(), r.defect) == fatal.end()) continue;
    std::ostringstream os;
    if (r.defect == MeshDefect::Empty)
      os << "mesh is empty (" << num_vertices << " vertices, " << num_faces << " faces)";
    else
      os << "mesh has " << r.count << " " << mesh_defect_name(r.defect) << ", first: " << r.example;
    return Status::error(StatusCode::InvalidMesh, os.str());
  }
  return Status::success();
}

std::string MeshReport::to_text() const {
  std::ostringstream os;
  os << "vertices: " << num_vertices << "\nfaces: " << num_faces << "\nedges: " << num_edges
     << "\nbounding box: [" << bbox_min.transpose() << "] - [" << bbox_max.transpose()
     << "] (diagonal " << bbox_diagonal << ")\ncomponents: " << num_components
     << "\nboundary loops: " << boundary_loops.size();
  if (!boundary_loops.empty()) {
    os << " (lengths";
    for (size_t i = 0; i < boundary_loops.size() && i < 10; ++i) os << " " << boundary_loops[i].size();
    if (boundary_loops.size() > 10) os << " ...";
    os << ")";
  }
  os << "\neuler characteristic: " << euler_characteristic << "\n";
  if (defects.empty()) {
    os << "defects: none\n";
  } else {
    os << "defects:\n";
    for (const auto& r : defects)
      os << "  " << mesh_defect_name(r.defect) << ": " << r.count << " (first: " << r.example << ")\n";
  }
  return os.str();
}

const std::vector<MeshDefect>& fatal_defects() {
  static const std::vector<MeshDefect> k{MeshDefect::Empty, MeshDefect::NonFiniteCoordinate,
                                         MeshDefect::IndexOutOfRange};
  return k;
}

const std::vector<MeshDefect>& manifold_defects() {
  static const std::vector<MeshDefect> k{
      MeshDefect::Empty,           MeshDefect::NonFiniteCoordinate, MeshDefect::IndexOutOfRange,
      MeshDefect::DegenerateFace,  MeshDefect::NonManifoldEdge,     MeshDefect::NonManifoldVertex};
  return k;
}

Status check_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                  const std::vector<MeshDefect>& fatal) {
  return validate_mesh(V, F).status(fatal);
}

namespace {

struct DefectCounter {
  MeshDefect defect;
  int count = 0;
  std::string example;
  void add(const std::string& ex) {
    if (count++ == 0) example = ex;
  }
  template <class Fn>
  void add_lazy(Fn make_example) {
    if (count++ == 0) example = make_example();
  }
};

std::string face_str(const Eigen::MatrixXi& F, int f) {
  std::ostringstream os;
  os << "face " << f << " (vertices " << F(f, 0) << ", " << F(f, 1) << ", " << F(f, 2) << ")";
  return os.str();
}

}  // namespace

MeshReport validate_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                         const ValidateOptions& opt) {
  MeshReport rep;
  const int n = static_cast<int>(V.rows());
  const int m = static_cast<int>(F.rows());
  rep.num_vertices = n;
  rep.num_faces = m;
  DefectCounter empty{MeshDefect::Empty}, nonfinite{MeshDefect::NonFiniteCoordinate},
      range{MeshDefect::IndexOutOfRange}, degenerate{MeshDefect::DegenerateFace},
      duplicate{MeshDefect::DuplicateFace}, nm_edge{MeshDefect::NonManifoldEdge},
      nm_vertex{MeshDefect::NonManifoldVertex}, unreferenced{MeshDefect::UnreferencedVertex},
      orientation{MeshDefect::InconsistentOrientation};

  if (n == 0 || m == 0) empty.add("no " + std::string(n == 0 ? "vertices" : "faces"));

  // Coordinates and bounding box over finite vertices.
  std::vector<char> finite(n, 1);
  bool any_finite = false;
  for (int v = 0; v < n; ++v) {
    if (!V.row(v).allFinite()) {
      finite[v] = 0;
      nonfinite.add_lazy([&] { return "vertex " + std::to_string(v); });
      continue;
    }
    const Eigen::Vector3d p = V.row(v).transpose();
    if (!any_finite) rep.bbox_min = rep.bbox_max = p;
    rep.bbox_min = rep.bbox_min.cwiseMin(p);
    rep.bbox_max = rep.bbox_max.cwiseMax(p);
    any_finite = true;
  }
  rep.bbox_diagonal = (rep.bbox_max - rep.bbox_min).norm();
  const double area_tol = opt.degenerate_area_tolerance * rep.bbox_diagonal * rep.bbox_diagonal;

  // Faces: index range, degeneracy; the valid ones go on to topology checks.
  std::vector<int> valid;
  valid.reserve(m);
  std::vector<char> referenced(n, 0);
  for (int f = 0; f < m; ++f) {
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a < 0 || b < 0 || c < 0 || a >= n || b >= n || c >= n) {
      range.add(face_str(F, f));
      continue;
    }
    referenced[a] = referenced[b] = referenced[c] = 1;
    if (a == b || b == c || a == c) {
      degenerate.add(face_str(F, f) + " repeats a vertex");
      continue;
    }
    if (finite[a] && finite[b] && finite[c]) {
      const Eigen::Vector3d e1 = (V.row(b) - V.row(a)).transpose();
      const Eigen::Vector3d e2 = (V.row(c) - V.row(a)).transpose();
      if (0.5 * e1.cross(e2).norm() <= area_tol) degenerate.add(face_str(F, f) + " has zero area");
    }
    valid.push_back(f);
  }
  for (int v = 0; v < n; ++v)
    if (!referenced[v]) unreferenced.add_lazy([&] { return "vertex " + std::to_string(v); });

  // Duplicate faces: same sorted vertex triple (faces bucketed by their smallest vertex, then
  // sorted within the bucket: linear overall).
  {
    const VertexBuckets by_min = bucket_by_vertex(n, static_cast<int>(valid.size()), [&](int i) {
      const int f = valid[i];
      const int x = F(f, 0), y = F(f, 1), z = F(f, 2);
      return (x == y || y == z || x == z) ? -1 : std::min(x, std::min(y, z));
    });
    std::vector<std::pair<std::array<int, 3>, int>> keys;
    for (int v = 0; v < n; ++v) {
      if (by_min.start[v + 1] - by_min.start[v] < 2) continue;
      keys.clear();
      for (int k = by_min.start[v]; k < by_min.start[v + 1]; ++k) {
        const int f = valid[by_min.items[k]];
        std::array<int, 3> t{F(f, 0), F(f, 1), F(f, 2)};
        std::sort(t.begin(), t.end());
        keys.push_back({t, f});
      }
      std::sort(keys.begin(), keys.end());
      for (size_t i = 1; i < keys.size(); ++i)
        if (keys[i].first == keys[i - 1].first)
          duplicate.add(face_str(F, keys[i].second) + " repeats face " + std::to_string(keys[i - 1].second));
    }
  }

  // Topology over valid, non-repeating faces.
  Eigen::MatrixXi Fv(valid.size(), 3);
  int rows = 0;
  for (int f : valid)
    if (F(f, 0) != F(f, 1) && F(f, 1) != F(f, 2) && F(f, 0) != F(f, 2)) Fv.row(rows++) = F.row(f);
  Fv.conservativeResize(rows, 3);

  const auto edges = edge_uses(Fv);
  rep.num_edges = static_cast<int>(edges.size());
  for (const auto& e : edges)
    if (e.faces > 2)
      nm_edge.add_lazy([&] {
        return "edge " + std::to_string(e.i) + "-" + std::to_string(e.j) + " in " +
               std::to_string(e.faces) + " faces";
      });

  // Orientation: a directed edge used twice means two neighbours disagree on winding (half-edges
  // bucketed by their first vertex).
  {
    const VertexBuckets by_from = bucket_by_vertex(n, rows * 3, [&](int h) { return Fv(h / 3, h % 3); });
    std::vector<int> to;
    for (int v = 0; v < n; ++v) {
      if (by_from.start[v + 1] - by_from.start[v] < 2) continue;
      to.clear();
      for (int k = by_from.start[v]; k < by_from.start[v + 1]; ++k) {
        const int h = by_from.items[k];
        to.push_back(Fv(h / 3, (h % 3 + 1) % 3));
      }
      std::sort(to.begin(), to.end());
      for (size_t i = 1; i < to.size(); ++i)
        if (to[i] == to[i - 1] && (i < 2 || to[i - 2] != to[i]))
          orientation.add_lazy([&] {
            return "edge " + std::to_string(v) + "->" + std::to_string(to[i]) + " appears twice";
          });
    }
  }

  // Non-manifold vertices: the faces around a vertex must form one fan (mesh/topology.h).
  for (const VertexFans& nv : non_manifold_vertices(Fv, n))
    nm_vertex.add_lazy([&] {
      return "vertex " + std::to_string(nv.vertex) + " joins " + std::to_string(nv.fans) + " fans";
    });

  // Components and boundary loops over referenced vertices.
  int ncomp = 0;
  const Eigen::VectorXi comp = vertex_components(Fv, n, &ncomp);
  std::vector<int> comp_faces(ncomp, 0);
  std::vector<char> comp_has_ref(ncomp, 0);
  for (int f = 0; f < rows; ++f) ++comp_faces[comp[Fv(f, 0)]];
  for (int v = 0; v < n; ++v)
    if (referenced[v]) comp_has_ref[comp[v]] = 1;
  for (int c = 0; c < ncomp; ++c)
    if (comp_has_ref[c] && comp_faces[c] > 0) rep.component_sizes.push_back(comp_faces[c]);
  rep.num_components = static_cast<int>(rep.component_sizes.size());
  rep.boundary_loops = boundary_loops(Fv, n);
  int nref = 0;
  for (int v = 0; v < n; ++v) nref += referenced[v];
  rep.euler_characteristic = nref - rep.num_edges + rows;

  for (const DefectCounter* d : {&empty, &nonfinite, &range, &degenerate, &duplicate, &nm_edge,
                                 &nm_vertex, &unreferenced, &orientation})
    if (d->count > 0) rep.defects.push_back({d->defect, d->count, d->example});
  return rep;
}

}  // namespace mm
