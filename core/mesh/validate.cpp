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
  explicit DefectCounter(MeshDefect d) : defect(d) {}
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
  // Row-major copies for the random accesses below (a point or a face in one cache line instead
  // of three; the loops are memory-bound at 1M vertices).
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> P = V.leftCols<3>();

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
      const Eigen::Vector3d e1 = (P.row(b) - P.row(a)).transpose();
      const Eigen::Vector3d e2 = (P.row(c) - P.row(a)).transpose();
      if (0.5 * e1.cross(e2).norm() <= area_tol) degenerate.add(face_str(F, f) + " has zero area");
    }
    valid.push_back(f);
  }
  for (int v = 0; v < n; ++v)
    if (!referenced[v]) unreferenced.add_lazy([&] { return "vertex " + std::to_string(v); });

  // Topology over valid, non-repeating faces (Fv; orig = their input rows), in one pass over
  // the corners around each vertex v (linear: one bucketing, then small per-vertex sorts). Each
  // corner of a face at v gives a spoke to its next vertex (half-edge v→next) and one to its
  // previous vertex (half-edge prev→v). Per neighbour w of v: the v→w count finds inconsistent
  // orientation; for w > v, the count of both directions is the number of faces on edge {v, w}
  // (> 2: non-manifold; 1: boundary); faces sharing a spoke form fans (> 1 fan: non-manifold
  // vertex); faces whose smallest vertex is v are compared for duplicates. Examples come in
  // ascending vertex order, as from edge_uses / non_manifold_vertices / boundary_loops.
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> Fv(valid.size(), 3);
  std::vector<int> orig;
  orig.reserve(valid.size());
  int rows = 0;
  for (int f : valid)
    if (F(f, 0) != F(f, 1) && F(f, 1) != F(f, 2) && F(f, 0) != F(f, 2)) {
      Fv.row(rows++) = F.row(f);
      orig.push_back(f);
    }
  Fv.conservativeResize(rows, 3);

  const VertexBuckets corners = bucket_by_vertex(n, rows * 3, [&](int h) { return Fv(h / 3, h % 3); });
  struct Spoke {
    int w;     // the other vertex
    int out;   // 1: half-edge v→w (w follows v in the face), 0: w→v
    int face;  // local face index at v
    bool operator<(const Spoke& o) const {
      return w != o.w ? w < o.w : out != o.out ? out < o.out : face < o.face;
    }
  };
  std::vector<Spoke> spokes;
  std::vector<int> parent;
  std::vector<std::pair<std::array<int, 3>, int>> keys;
  std::vector<std::pair<int, int>> boundary;  // boundary half-edges a→b
  int num_edges = 0;
  for (int v = 0; v < n; ++v) {
    const int c0 = corners.start[v], c1 = corners.start[v + 1], nc = c1 - c0;
    if (nc == 0) continue;
    spokes.clear();
    keys.clear();
    for (int k = 0; k < nc; ++k) {
      const int h = corners.items[c0 + k], f = h / 3, c = h % 3;
      const int next = Fv(f, (c + 1) % 3), prev = Fv(f, (c + 2) % 3);
      spokes.push_back({next, 1, k});
      spokes.push_back({prev, 0, k});
      if (v < next && v < prev) {
        std::array<int, 3> t{Fv(f, 0), Fv(f, 1), Fv(f, 2)};
        std::sort(t.begin(), t.end());
        keys.push_back({t, orig[f]});
      }
    }
    std::sort(spokes.begin(), spokes.end());
    parent.resize(nc);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&parent](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (size_t i = 0; i < spokes.size();) {
      size_t e = i;
      int outs = 0;
      while (e < spokes.size() && spokes[e].w == spokes[i].w) {
        outs += spokes[e].out;
        if (e > i) {
          const int ra = find(spokes[e].face), rb = find(spokes[e - 1].face);
          if (ra != rb) parent[ra] = rb;
        }
        ++e;
      }
      const int w = spokes[i].w, uses = static_cast<int>(e - i);
      if (outs >= 2)
        orientation.add_lazy([&] { return "edge " + std::to_string(v) + "->" + std::to_string(w) + " appears twice"; });
      if (w > v) {
        ++num_edges;
        if (uses > 2)
          nm_edge.add_lazy([&] {
            return "edge " + std::to_string(v) + "-" + std::to_string(w) + " in " + std::to_string(uses) + " faces";
          });
        if (uses == 1) boundary.push_back(outs == 1 ? std::make_pair(v, w) : std::make_pair(w, v));
      }
      i = e;
    }
    if (nc >= 2) {
      int fans = 0;
      for (int k = 0; k < nc; ++k) fans += find(k) == k;
      if (fans > 1)
        nm_vertex.add_lazy([&] { return "vertex " + std::to_string(v) + " joins " + std::to_string(fans) + " fans"; });
    }
    if (keys.size() >= 2) {
      std::sort(keys.begin(), keys.end());
      for (size_t i = 1; i < keys.size(); ++i)
        if (keys[i].first == keys[i - 1].first)
          duplicate.add(face_str(F, keys[i].second) + " repeats face " + std::to_string(keys[i - 1].second));
    }
  }
  rep.num_edges = num_edges;

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
  rep.boundary_loops = chain_boundary_loops(n, boundary);
  int nref = 0;
  for (int v = 0; v < n; ++v) nref += referenced[v];
  rep.euler_characteristic = nref - rep.num_edges + rows;

  for (const DefectCounter* d : {&empty, &nonfinite, &range, &degenerate, &duplicate, &nm_edge,
                                 &nm_vertex, &unreferenced, &orientation})
    if (d->count > 0) rep.defects.push_back({d->defect, d->count, d->example});
  return rep;
}

}  // namespace mm
