// meshmorph info | convert | eigs — inspection and conversion of mesh files.
#include <iomanip>
#include <iostream>

#include "cli.h"
#include "common/colormap.h"
#include "io/asset.h"
#include "io/info_report.h"
#include "mesh/validate.h"
#include "spectral/spectral_basis.h"

namespace mm::cli {
namespace {

int run_info(const std::vector<std::string>& argv) {
  Args args;
  Status s = args.parse(argv, {"json", "help"});
  if (!s.ok()) return report("info", s);
  if (args.has("help") || args.positional().size() != 1) {
    std::cout << "usage: meshmorph info FILE [--json]\n"
                 "  counts, bounding box, validation report (defects with counts and a first example),\n"
                 "  components and boundary loops of the welded mesh; --json prints one JSON object.\n";
    return args.has("help") ? 0 : 2;
  }
  const io::LoadResult lr = io::load_asset(args.positional()[0]);
  if (!lr.status.ok()) return report("info", lr.status);
  const io::InfoReport info = io::info_report(lr.asset);
  std::cout << (args.has("json") ? info.json + "\n" : info.text);
  return 0;
}

int run_convert(const std::vector<std::string>& argv) {
  Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return report("convert", s);
  if (args.has("help") || args.positional().size() != 2) {
    std::cout << "usage: meshmorph convert IN OUT\n"
                 "  formats by extension: .glb .gltf .obj .off .ply. Same-format output keeps the whole\n"
                 "  document; across formats, what the target format can hold is kept.\n";
    return args.has("help") ? 0 : 2;
  }
  const io::LoadResult lr = io::load_asset(args.positional()[0]);
  if (!lr.status.ok()) return report("convert", lr.status);
  return report("convert", io::save_asset(lr.asset, lr.asset.weld.V, args.positional()[1]));
}

int run_eigs(const std::vector<std::string>& argv) {
  Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return report("eigs", s);
  SpectralBasisOptions opt;
  opt.k = args.get_int("k", opt.k, &s);
  opt.tolerance = args.get_double("tolerance", opt.tolerance, &s);
  if (!parse_eigen_solver(args.get("solver", "auto"), &opt.solver)) s = Status::error(StatusCode::InvalidArgument, "--solver must be auto, block or spectra");
  const int show = args.get_int("show", 1, &s);
  const std::string out = args.get("out");
  if (!s.ok()) return report("eigs", s);
  if (args.has("help") || args.positional().size() != 1) {
    std::cout << "usage: meshmorph eigs FILE [-k " << SpectralBasisOptions{}.k << "] [--tolerance "
              << SpectralBasisOptions{}.tolerance << "] [--solver auto|block|spectra] [--out COLORS.glb --show I]\n"
              << "  the k smallest eigenpairs of W phi = lambda A phi (cotangent stiffness, Voronoi mass).\n"
                 "  --solver: block Lanczos, Spectra's Lanczos, or auto (block when the Krylov basis of\n"
                 "  n x (2k+1) doubles exceeds 20 MiB, where it is faster; spectral/spectral_basis.h).\n"
                 "  --out writes the mesh with eigenfunction I (default 1) as vertex colours (blue < 0 < red).\n";
    return args.has("help") ? 0 : 2;
  }
  for (const auto& u : args.unused()) return report("eigs", Status::error(StatusCode::InvalidArgument, "unknown option --" + u));
  const io::LoadResult lr = io::load_asset(args.positional()[0]);
  if (!lr.status.ok()) return report("eigs", lr.status);
  const Mesh m = lr.asset.mesh();
  if (Status c = check_mesh(m.V, m.F, manifold_defects()); !c.ok()) return report("eigs", c);
  const SpectralBasis b = spectral_basis(m.V, m.F, opt, terminal_progress());
  if (!b.status.ok()) return report("eigs", b.status);
  std::cout << "# " << b.eigenvalues.size() << " eigenvalues of W phi = lambda A phi (" << m.num_vertices()
            << " vertices, " << b.iterations << " restarts, " << b.operations << " solves)\n";
  std::cout << std::setprecision(10);
  for (int i = 0; i < b.eigenvalues.size(); ++i) std::cout << i << " " << b.eigenvalues[i] << "\n";
  if (!out.empty()) {
    if (show < 0 || show >= b.vectors.cols())
      return report("eigs", Status::error(StatusCode::InvalidArgument,
                                          "--show must be in 0.." + std::to_string(b.vectors.cols() - 1)));
    return report("eigs", io::save_mesh(out, m.V, m.F, diverging_colors(b.vectors.col(show))));
  }
  return 0;
}

}  // namespace

MM_COMMAND(info, "counts, bounding box, validation report, components, boundary loops", run_info);
MM_COMMAND(convert, "convert between .glb/.gltf/.obj/.off/.ply, keeping the document", run_convert);
MM_COMMAND(eigs, "smallest Laplace-Beltrami eigenpairs; eigenfunctions as vertex colours", run_eigs);

}  // namespace mm::cli
