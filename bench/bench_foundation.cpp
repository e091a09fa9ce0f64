// Foundation stages: load, weld, operator assembly, factorization, eigs k=20 / k=100 on
// four meshes of increasing size. Peer figures: PEERS.md (libigl v2.6 / Spectra + LDLT, g++ -O3).
// armadillo (14,587) and michael3 (52,565) are the meshes of its side-by-side table, measured on
// this machine kind beside MeshMorph: those rows compare like with like. camelhead and horse0 sit
// beside the first table's 10.0k / 25.9k columns, measured on meshes of similar, not equal, size
// and on a CPU that ran the peer 20–40 % slower than the side-by-side one.
#include <cstdio>
#include <filesystem>

#include "bench.h"
#include "io/asset.h"
#include "linalg/spd_solver.h"
#include "mesh/topology.h"
#include "mesh/weld.h"
#include "operators/operators.h"
#include "spectral/spectral_basis.h"

namespace mm::bench {
namespace {

struct MeshCase {
  std::string repo, shared;  // data paths
  std::string peer_column;   // which PEERS.md figures the peer column holds
  std::string assembly_peer, eigs20_peer, eigs100_peer;
};

void foundation_suite(Context& ctx) {
  const std::vector<MeshCase> cases = {
      {"edit/camelhead.ply", "edit/camelhead.off", "PEERS.md first table, 10.0k V column", "igl 8 ms", "Spectra+LDLT 80 ms", "Spectra+LDLT 692 ms"},
      {"edit/armadillo.ply", "edit/armadillo.obj", "PEERS.md side-by-side table", "igl 10.4 ms", "Spectra+LDLT 190 ms", "Spectra+LDLT 1.24 s"},
      {"pose/horse0.ply", "pose/tosca/horse0.off", "PEERS.md first table, 25.9k V column", "igl 27 ms", "Spectra+LDLT 298 ms", "Spectra+LDLT 2.89 s"},
      {"", "pose/tosca/michael3.off", "PEERS.md side-by-side table", "igl 51.1 ms", "Spectra+LDLT 711 ms", "Spectra+LDLT 5.13 s"},
  };
  for (const auto& c : cases) {
    const std::string path = ctx.find_data(c.repo, c.shared);
    if (path.empty()) {
      std::fprintf(stderr, "  skipping %s (not in data/ and ../shared/data is absent)\n", c.shared.c_str());
      continue;
    }
    const std::string name = std::filesystem::path(path).stem().string();
    io::LoadResult lr;
    const double t_load = ctx.time_ms([&] { lr = io::load_asset(path); }, 3);
    if (!lr.status.ok()) {
      std::fprintf(stderr, "  %s: %s\n", path.c_str(), lr.status.message.c_str());
      continue;
    }
    const Mesh m = lr.asset.mesh();
    const int n = m.num_vertices();
    const std::string& peer_note = c.peer_column;
    ctx.add({"foundation", name, n, "load", t_load, "", std::filesystem::path(path).extension().string()});
    WeldResult w;
    ctx.add({"foundation", name, n, "weld",
             ctx.time_ms([&] { w = weld_vertices(lr.asset.V_raw, lr.asset.F_raw); }, 5), "", ""});
    std::vector<std::vector<int>> loops;
    ctx.add({"foundation", name, n, "boundary loops",
             ctx.time_ms([&] { loops = boundary_loops(m.F, n); }, 5), "", std::to_string(loops.size()) + " loops"});
    SparseMatrix W;
    Eigen::VectorXd a;
    ctx.add({"foundation", name, n, "cotan + Voronoi mass",
             ctx.time_ms([&] { W = cotan_stiffness(m.V, m.F); a = mass_diagonal(m.V, m.F); }, 5), c.assembly_peer,
             peer_note});
    SpdSolver solver;
    Status fs;
    const SparseMatrix Msys = W + SparseMatrix(a.asDiagonal()) * 1e-3;
    ctx.add({"foundation", name, n, "LDLT factor (W + 1e-3 A)", ctx.time_ms([&] { fs = solver.factor(Msys); }, 3), "",
             fs.ok() ? "" : fs.message});
    Eigen::MatrixXd X;
    const Eigen::MatrixXd B = m.V;
    ctx.add({"foundation", name, n, "solve, 3 RHS", ctx.time_ms([&] { (void)solver.solve(B, &X); }, 5), "", ""});
    for (int k : {20, 100}) {
      if (ctx.quick && k == 100) continue;
      SpectralBasisOptions opt;
      opt.k = k;
      SpectralBasis b;
      const double t = ctx.time_ms([&] { b = spectral_basis(W, a, opt); }, k == 20 ? 3 : 1);
      const auto note = [](const SpectralBasis& r) {
        return r.status.ok() ? std::string(r.solver) + ", " + std::to_string(r.operations) + " solves, " + std::to_string(r.passes) +
                                   (r.passes == 1 ? " pass" : " passes")
                             : r.status.message;
      };
      ctx.add({"foundation", name, n, "eigs k=" + std::to_string(k), t, k == 20 ? c.eigs20_peer : c.eigs100_peer, note(b)});
      // The other solver on the same matrices as a control row (where Auto chose block Lanczos,
      // Spectra's; where it chose Spectra, the block solver), to watch the crossover.
      const bool block = std::string(b.solver) == "block Lanczos";
      if (block || std::string(b.solver) == "Spectra") {
        opt.solver = block ? EigenSolverKind::Spectra : EigenSolverKind::BlockLanczos;
        const double ts = ctx.time_ms([&] { b = spectral_basis(W, a, opt); }, k == 20 ? 3 : 1);
        ctx.add({"foundation", name, n, "eigs k=" + std::to_string(k) + (block ? " (Spectra control)" : " (block control)"), ts, "", note(b)});
      }
    }
  }
}

// Loading at scale (issue 18): weld and boundary tracing of an axis-aligned k by k grid (every x
// coordinate shared by k vertices: the case that was quadratic), at 10k, 100k and 1M vertices;
// the time should grow linearly.
void loading_suite(Context& ctx) {
  for (int k : {100, 316, 1000}) {
    if (ctx.quick && k == 1000) continue;
    Eigen::MatrixXd V(static_cast<Eigen::Index>(k) * k, 3);
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) V.row(static_cast<Eigen::Index>(j) * k + i) << i, j, 0.0;
    Eigen::MatrixXi F(2 * static_cast<Eigen::Index>(k - 1) * (k - 1), 3);
    Eigen::Index f = 0;
    for (int j = 0; j + 1 < k; ++j)
      for (int i = 0; i + 1 < k; ++i) {
        const int a = j * k + i, b = a + 1, c = a + k, d = c + 1;
        F.row(f++) << a, b, d;
        F.row(f++) << a, d, c;
      }
    const int n = static_cast<int>(V.rows());
    const std::string name = "grid " + std::to_string(k) + "x" + std::to_string(k);
    WeldResult w;
    ctx.add({"loading", name, n, "weld", ctx.time_ms([&] { w = weld_vertices(V, F); }, 3), "", ""});
    std::vector<std::vector<int>> loops;
    ctx.add({"loading", name, n, "boundary loops", ctx.time_ms([&] { loops = boundary_loops(F, n); }, 3), "",
             std::to_string(loops.size()) + " loop(s)"});
  }
}

}  // namespace

MM_BENCH(foundation, foundation_suite);
MM_BENCH(loading, loading_suite);

}  // namespace mm::bench
