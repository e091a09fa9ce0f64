// Edit stages (paper 001): precompute split into stencils / assembly / factor / handle basis /
// Poisson factor, then drag (handle basis), drag with 3 back-substitutions, finalize (polar +
// second solve). Setup: ROI = the whole mesh, handle = the top 4% along the long axis, fixed = the
// bottom 4% (hundreds of constrained vertices, like the ARAP row of PEERS.md).
// Peers: paper 001 Table 1 (Armadillo, 48,027 free vertices, Pentium IV 3.2 GHz), the ARAP precompute
// and LᵀL drag of PEERS.md's side-by-side table (armadillo and michael3, this machine kind) and the libigl
// Laplacian-editing rows of PEERS.md (50.0k V column).
#include <cstdio>
#include <filesystem>

#include "bench.h"
#include "edit/laplacian_editor.h"
#include "io/asset.h"

namespace mm::bench {
namespace {

struct EditBenchCase {
  std::string repo, shared;
  bool paper_size;  // compare with the paper's 48k Armadillo row
  // PEERS.md's side-by-side table on the same mesh: libigl's ARAP precompute (issue 18 asks
  // ≤ 1.3× of it at 52k) and its LᵀL drag (one 3-column solve).
  std::string arap_peer, ltl_drag_peer;
};

std::vector<int> edit_bench_slab(const Eigen::MatrixXd& V, int axis, double fraction, bool high) {
  const double lo = V.col(axis).minCoeff(), hi = V.col(axis).maxCoeff();
  std::vector<int> out;
  for (int i = 0; i < V.rows(); ++i) {
    const double t = (V(i, axis) - lo) / (hi - lo);
    if (high ? t >= 1 - fraction : t <= fraction) out.push_back(i);
  }
  return out;
}

void edit_suite(Context& ctx) {
  const std::vector<EditBenchCase> cases = {
      {"edit/armadillo.ply", "edit/armadillo.obj", false, "ARAP 163 ms", "LtL drag 8.6 ms"},
      {"", "pose/tosca/michael3.off", true, "ARAP 750 ms", "LtL drag 37.3 ms"},
  };
  for (const auto& c : cases) {
    if (ctx.quick && c.paper_size) continue;
    const std::string path = ctx.find_data(c.repo, c.shared);
    if (path.empty()) {
      std::fprintf(stderr, "  skipping %s (not in data/ and ../shared/data is absent)\n", c.shared.c_str());
      continue;
    }
    const std::string name = std::filesystem::path(path).stem().string();
    io::LoadResult lr = io::load_asset(path);
    if (!lr.status.ok()) {
      std::fprintf(stderr, "  %s: %s\n", path.c_str(), lr.status.message.c_str());
      continue;
    }
    const Mesh m = lr.asset.mesh();
    const int n = m.num_vertices();
    Eigen::Index axis;
    (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).maxCoeff(&axis);
    EditRegion region;
    region.handles = {edit_bench_slab(m.V, static_cast<int>(axis), 0.04, true)};
    region.fixed = edit_bench_slab(m.V, static_cast<int>(axis), 0.04, false);
    const Eigen::Vector3d pivot = m.V.colwise().mean().transpose();
    Eigen::Vector3d rot_axis = Eigen::Vector3d::Zero();
    rot_axis[(axis + 1) % 3] = 1;
    const double diag = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm();
    const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0.1 * diag, 0, 0), rot_axis, 0.6, pivot);

    LaplacianEditor ed;
    Status s;
    const double t_pre = ctx.time_ms([&] { s = ed.precompute(m.V, m.F, region); }, ctx.quick ? 1 : 2);
    if (!s.ok()) {
      std::fprintf(stderr, "  %s: %s\n", name.c_str(), s.message.c_str());
      continue;
    }
    const EditStats& st = ed.stats();
    const std::string setup = std::to_string(st.free_vertices) + " free, " + std::to_string(region.handles[0].size()) +
                              " handle, " + std::to_string(st.degenerate_vertices) + " degenerate";
    const bool p = c.paper_size;
    ctx.add({"edit", name, n, "precompute (total)", t_pre, c.arap_peer, setup});
    ctx.add({"edit", name, n, "  stencils + degenerate", st.stencil_ms, "", ""});
    ctx.add({"edit", name, n, "  assemble AtA (Eq. 7)", st.assembly_ms, "",
             "nnz(lower) " + std::to_string(st.system_nonzeros)});
    ctx.add({"edit", name, n, "  factor AtA (Eq. 7)", st.factor_ms, p ? "paper 001: 4.813 s" : "",
             p ? "libigl LtL factor 1.54 s" : ""});
    ctx.add({"edit", name, n, "  handle basis (4 solves/handle)", st.basis_ms, "",
             std::to_string(st.basis_refinements) + " refinement step(s)"});
    ctx.add({"edit", name, n, "  Poisson factor (Eq. 9/10)", st.poisson_ms, p ? "paper 001: 0.875 s" : "", ""});
    EditResult r;
    ctx.add({"edit", name, n, "drag (handle basis)", ctx.time_ms([&] { r = ed.drag({T}); }, 5),
             p ? "paper 001 solve: 0.188 s" : "", p ? "libigl drag 61 ms" : ""});
    Eigen::MatrixXd targets = m.V;
    for (int v : region.handles[0]) targets.row(v) = T.apply(m.V.row(v).transpose()).transpose();
    const double t_pos = ctx.time_ms([&] { r = ed.drag_positions(targets); }, 5);
    ctx.add({"edit", name, n, "drag (3 back-substitutions)", t_pos, p ? "paper 001 solve: 0.188 s" : "",
             std::string(p ? "libigl drag 61 ms; " : "") + std::to_string(r.refinements) + " refinement step(s)"});
    {
      // The interactive preview: one plain solve (like the peer's LᵀL drag); its distance to the
      // refined drag above, as a fraction of the diagonal.
      const Eigen::MatrixXd refined = r.V;
      EditResult q;
      const double t_prev = ctx.time_ms([&] { q = ed.drag_positions(targets, 0); }, 5);
      const double off = q.status.ok() ? (q.V - refined).rowwise().norm().maxCoeff() / diag : -1;
      char note[96];
      std::snprintf(note, sizeof note, "max %.1e of the diagonal from the refined drag", off);
      ctx.add({"edit", name, n, "drag preview (1 solve)", t_prev, c.ltl_drag_peer, note});
    }
    ctx.add({"edit", name, n, "finalize (polar + solve)", ctx.time_ms([&] { r = ed.finalize(); }, 5),
             p ? "paper 001: 0.985 + 0.078 s" : "", r.status.ok() ? "" : r.status.message});
  }
}

}  // namespace

MM_BENCH(edit, edit_suite);

}  // namespace mm::bench
