// Exploratory probes for core/edit (disabled; run with --gtest_also_run_disabled_tests
// --gtest_filter='EditProbe.*'). They print the metrics used to choose the thresholds of
// tests/edit_test.cpp and, with MM_EDIT_DUMP=<folder>, write OBJ files for visual checks.
// Environment: MM_BAR (mesh file under data/), MM_SUB (midpoint subdivisions), MM_THR (sweep the
// degenerate threshold).
#include <cstdio>
#include <cstdlib>

#include "edit_test_util.h"
#include "mesh/topology.h"
#include "metrics/edit_metrics.h"

namespace {

using namespace mm;
using namespace mm::edit_test;

TEST(EditProbe, DISABLED_BarTuning) {
  const char* file = std::getenv("MM_BAR") ? std::getenv("MM_BAR") : "edit/bar.ply";
  const int sub = std::getenv("MM_SUB") ? std::atoi(std::getenv("MM_SUB")) : 0;
  struct Cfg {
    const char* name;
    LaplacianEditOptions opt;
  };
  std::vector<Cfg> cfgs(5);
  if (std::getenv("MM_THR")) {
    cfgs.resize(6);
    for (int k = 0; k < 6; ++k) cfgs[k] = Cfg{};
    const double thr[6] = {2e5, 1e4, 1e3, 100, 30, 10};
    static char names[6][16];
    for (int k = 0; k < 6; ++k) {
      std::snprintf(names[k], 16, "thr%g", thr[k]);
      cfgs[k].name = names[k];
      cfgs[k].opt.condition_threshold = thr[k];
    }
  } else {
  cfgs[0].name = "default";
  cfgs[1].name = "rings1";
  cfgs[1].opt.coherence_rings = 1;
  cfgs[2].name = "rings3";
  cfgs[2].opt.coherence_rings = 3;
  cfgs[3].name = "gradc";
  cfgs[3].opt.gradient_constraint_weight = 1;
  cfgs[4].name = "uniform";
  cfgs[4].opt.weights = LaplacianWeights::Uniform;
  }
  for (int bend = 0; bend < 2; ++bend)
    for (const Cfg& cfg : cfgs) {
      BarCase b = bar_case(bend, file, sub);
      LaplacianEditor ed;
      ASSERT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, b.region, cfg.opt).ok());
      EditResult p = ed.drag({b.transform});
      ASSERT_TRUE(p.status.ok()) << p.status.message;
      EditResult f = ed.finalize();
      ASSERT_TRUE(f.status.ok()) << f.status.message;
      LaplacianEditOptions nopt = cfg.opt;
      nopt.method = EditMethod::NaiveLaplacian;
      LaplacianEditResult nv = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform}, nopt);
      ASSERT_TRUE(nv.status.ok()) << nv.status.message;
      const Eigen::VectorXd rp = local_rigidity_error(b.mesh.V, p.V, b.mesh.F);
      const Eigen::VectorXd rf = local_rigidity_error(b.mesh.V, f.V, b.mesh.F);
      const Eigen::VectorXd rn = local_rigidity_error(b.mesh.V, nv.V, b.mesh.F);
      std::printf("%s %-8s mean pre %.4f fin %.4f naive %.4f (x%.2f) | p90 %.3f %.3f %.3f | max %.3f %.3f %.3f | inv %zu/%zu | shear %.3f->%.3f\n",
                  bend ? "bend " : "twist", cfg.name, rp.mean(), rf.mean(), rn.mean(), rn.mean() / rf.mean(),
                  quantile(rp, 0.9), quantile(rf, 0.9), quantile(rn, 0.9), rp.maxCoeff(),
                  rf.maxCoeff(), rn.maxCoeff(), inverted_faces(b.mesh.V, f.V, b.mesh.F).size(),
                  inverted_faces(b.mesh.V, nv.V, b.mesh.F).size(), gradient_shear(ed.gradients()).mean(),
                  gradient_shear(fitted_gradients(b.mesh.V, f.V, b.mesh.F)).mean());
    }
}

// Writes rest / preview / final / naive OBJs to $MM_EDIT_DUMP (a folder) for visual checks.
TEST(EditProbe, DISABLED_BarDump) {
  const char* dir = std::getenv("MM_EDIT_DUMP");
  if (!dir) GTEST_SKIP();
  for (int bend = 0; bend < 2; ++bend) {
    BarCase b = bar_case(bend, std::getenv("MM_BAR") ? std::getenv("MM_BAR") : "edit/bar.ply",
                              std::getenv("MM_SUB") ? std::atoi(std::getenv("MM_SUB")) : 0);
    LaplacianEditor ed;
    ASSERT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, b.region).ok());
    EditResult p = ed.drag({b.transform});
    EditResult f = ed.finalize();
    LaplacianEditOptions nopt;
    nopt.method = EditMethod::NaiveLaplacian;
    LaplacianEditResult nv = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform}, nopt);
    const std::string tag = std::string(dir) + (bend ? "/bend_" : "/twist_");
    io::save_mesh(tag + "rest.obj", b.mesh.V, b.mesh.F);
    io::save_mesh(tag + "preview.obj", p.V, b.mesh.F);
    io::save_mesh(tag + "final.obj", f.V, b.mesh.F);
    io::save_mesh(tag + "naive.obj", nv.V, b.mesh.F);
  }
}

TEST(EditProbe, DISABLED_Limb) {
  for (const char* file : {"anim/human_woman.ply", "edit/decimated-knight.ply"}) {
    Mesh m = load(file);
    const Eigen::MatrixXd& V = m.V;
    const double xmin = V.col(0).minCoeff(), xmax = V.col(0).maxCoeff(), w = xmax - xmin;
    const double ymin = V.col(1).minCoeff(), ymax = V.col(1).maxCoeff();
    EditRegion region;
    std::vector<int> hand, roi, fixed;
    const double xc = 0.5 * (xmin + xmax);
    for (int i = 0; i < V.rows(); ++i) {
      const double t = (V(i, 0) - xc) / (0.5 * w);  // -1..1 across the arm span
      if (t > 0.85) hand.push_back(i);
      if (t > 0.3) roi.push_back(i);
    }
    region.handles = {hand};
    region.roi = roi;
    for (double lift : {0.15, 0.3, 0.5}) {
      const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0, lift * (ymax - ymin), 0),
                                                            Eigen::Vector3d::Zero(), 0, Eigen::Vector3d::Zero());
      LaplacianEditor ed;
      ASSERT_TRUE(ed.precompute(V, m.F, region).ok());
      EditResult p = ed.drag({T});
      EditResult f = ed.finalize();
      LaplacianEditOptions nopt;
      nopt.method = EditMethod::NaiveLaplacian;
      LaplacianEditResult nv = laplacian_edit(V, m.F, region, {T}, nopt);
      std::vector<int> free;
      std::vector<char> isH(V.rows(), 0);
      for (int v : hand) isH[v] = 1;
      for (int v : roi)
        if (!isH[v]) free.push_back(v);
      const auto dp = detail_preservation(V, p.V, m.F, free), df = detail_preservation(V, f.V, m.F, free),
                 dn = detail_preservation(V, nv.V, m.F, free);
      const auto dh = detail_preservation(V, f.V, m.F, hand);
      std::printf("%s lift %.2f: roi %zu hand %zu | angle rest %.2f preview %.2f final %.2f naive %.2f | hand final %.2f | rigid fin %.4f naive %.4f | inv %zu %zu\n",
                  file, lift, roi.size(), hand.size(), dp.rest_mean_angle_deg, dp.mean_angle_deg, df.mean_angle_deg,
                  dn.mean_angle_deg, dh.mean_angle_deg,
                  mean_over(local_rigidity_error(V, f.V, m.F), free), mean_over(local_rigidity_error(V, nv.V, m.F), free),
                  inverted_faces(V, f.V, m.F).size(), inverted_faces(V, nv.V, m.F).size());
      if (const char* dir = std::getenv("MM_EDIT_DUMP")) {
        const std::string tag = std::string(dir) + "/limb_" + std::to_string(int(lift * 100)) + "_" + (file[0] == 'a' ? "woman" : "knight");
        io::save_mesh(tag + "_final.obj", f.V, m.F);
        io::save_mesh(tag + "_naive.obj", nv.V, m.F);
        io::save_mesh(tag + "_preview.obj", p.V, m.F);
        io::save_mesh(tag + "_rest.obj", V, m.F);
      }
    }
  }
}
TEST(EditProbe, DISABLED_Planar) {
  for (auto weights : {LaplacianWeights::Cotangent, LaplacianWeights::Uniform})
    for (double sd : {0.2, 10.0}) {
      Mesh m = planar_patch(20);
      EditRegion region;
      std::vector<int> center, boundary;
      for (int i = 0; i < m.V.rows(); ++i) {
        const double r = (m.V.row(i) - Eigen::RowVector3d(0.5, 0.5, 0)).norm();
        if (r < 0.12) center.push_back(i);
        const double x = m.V(i, 0), y = m.V(i, 1);
        if (x == 0 || y == 0 || x == 1 || y == 1) boundary.push_back(i);
      }
      region.handles = {center};
      region.fixed = boundary;
      LaplacianEditOptions opt;
      opt.weights = weights;
      opt.displacement_scale = sd;
      LaplacianEditor ed;
      Status s = ed.precompute(m.V, m.F, region, opt);
      ASSERT_TRUE(s.ok()) << s.message;
      const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0, 0, 0.3), Eigen::Vector3d(1, 0, 0), 0.5,
                                                            Eigen::Vector3d(0.5, 0.5, 0));
      EditResult p = ed.drag({T});
      ASSERT_TRUE(p.status.ok()) << p.status.message;
      EditResult f = ed.finalize();
      const auto adj = vertex_adjacency(m.F, m.V.rows());
      std::vector<char> disp(m.V.rows(), 0), fixedmask(m.V.rows(), 0);
      for (int v : ed.displaced_vertices()) disp[v] = 1;
      for (int v : boundary) fixedmask[v] = 1;
      for (int v : center) fixedmask[v] = 1;
      double dd = 0, dn = 0, md = 0, fd = 0;
      int nd = 0, nn = 0;
      double h = ed.stats().mean_edge_length;
      for (int i = 0; i < m.V.rows(); ++i) {
        if (fixedmask[i]) continue;
        const double d = plane_distance(p.V, i, adj[i]) / h;
        const double d2 = plane_distance(f.V, i, adj[i]) / h;
        if (disp[i]) {
          dd += d;
          md = std::max(md, d);
          fd += d2;
          ++nd;
        } else {
          dn += d;
          ++nn;
        }
      }
      std::printf("%s sdisp %.1f: degenerate %d displaced %d widened %d maxcond %.3g | preview plane dist/h displaced mean %.4f max %.4f, others %.4f | final displaced %.4f | rigid fin %.4f\n",
                  weights == LaplacianWeights::Cotangent ? "cot" : "uni", sd, ed.stats().degenerate_vertices,
                  ed.stats().displaced_vertices, ed.stats().widened_stencils, ed.stats().max_condition, dd / nd, md, dn / nn,
                  fd / nd, local_rigidity_error(m.V, f.V, m.F).mean());
      if (const char* dir = std::getenv("MM_EDIT_DUMP")) {
        io::save_mesh(std::string(dir) + "/planar_" + std::to_string(int(sd)) + "_preview.obj", p.V, m.F);
        io::save_mesh(std::string(dir) + "/planar_" + std::to_string(int(sd)) + "_final.obj", f.V, m.F);
      }
    }
}
// Soft constraints: how far the handle vertices are from their targets, and where soft and hard
// results differ.
TEST(EditProbe, DISABLED_Soft) {
  BarCase b = bar_case(true);
  LaplacianEditResult hard = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform});
  for (double w : {1e2, 1e4, 1e6, 1e8}) {
    LaplacianEditOptions opt;
    opt.soft_constraint_weight = w;
    LaplacianEditResult soft = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform}, opt);
    double hp = 0, hf = 0;
    for (int v : b.region.handles[0]) {
      const Eigen::RowVector3d t = b.transform.apply(b.mesh.V.row(v).transpose()).transpose();
      hp = std::max(hp, (soft.preview.row(v) - t).norm());
      hf = std::max(hf, (soft.V.row(v) - t).norm());
    }
    Eigen::Index worst;
    const double d = (hard.V - soft.V).rowwise().norm().maxCoeff(&worst);
    std::printf("w %.0e: handle error preview %.2e final %.2e | max diff preview %.2e final %.2e at %ld\n", w, hp, hf,
                (hard.preview - soft.preview).rowwise().norm().maxCoeff(), d, static_cast<long>(worst));
  }
}

// Exact numbers behind the docs: configuration-invariance error, identity error.
TEST(EditProbe, DISABLED_Invariance) {
  BarCase b = bar_case(true);
  const Eigen::MatrixXd& V = b.mesh.V;
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(1, 2, 3), 2.0,
                                                        Eigen::Vector3d(0.1, 0.1, 0.1), 1.7);
  EditRegion region;
  region.handles = {b.region.handles[0], b.region.fixed};
  Eigen::MatrixXd expected(V.rows(), 3);
  for (int i = 0; i < V.rows(); ++i) expected.row(i) = T.apply(V.row(i).transpose()).transpose();
  LaplacianEditor ed;
  ASSERT_TRUE(ed.precompute(V, b.mesh.F, region).ok());
  const double diag = bounding_box_diagonal(V);
  EditResult p = ed.drag({T, T});
  EditResult f = ed.finalize(FeatureSize::Scale);
  std::printf("invariance: preview %.3g·diag, finalize(scale) %.3g·diag\n", (p.V - expected).cwiseAbs().maxCoeff() / diag,
              (f.V - expected).cwiseAbs().maxCoeff() / diag);
  LaplacianEditor id;
  ASSERT_TRUE(id.precompute(V, b.mesh.F, b.region).ok());
  EditResult q = id.drag({HandleTransform{}});
  EditResult g = id.finalize();
  std::printf("identity: preview %.3g, finalize %.3g\n", (q.V - V).cwiseAbs().maxCoeff(), (g.V - V).cwiseAbs().maxCoeff());
}

}  // namespace
