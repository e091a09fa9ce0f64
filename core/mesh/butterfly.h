// Butterfly subdivision (Dyn, Levin, Gregory 1990) and its exact removal, for parts that are too
// coarse for stable coupled quasi-harmonic bases (paper 000 Sec. 4.3: "refine them once or
// twice ... remove the inserted vertices such that the new pose has the same connectivity").
//
// One level splits every triangle into four. The scheme is interpolating: the #V input vertices
// keep their indices and positions (rows 0..#V−1 of the output), and one vertex per undirected
// edge follows (edges in ascending (i, j) order). Edge rules (w = 1/16, the paper's tension):
//  - interior edge (a, b) with opposite vertices c, d and the four wing vertices e..h opposite
//    the edges (a,c), (b,c), (a,d), (b,d): ½(a+b) + ⅛(c+d) − 1/16(e+f+g+h);
//  - interior edge with a missing wing (a wing edge on the boundary or non-manifold): Loop's
//    affine-invariant 3/8(a+b) + 1/8(c+d) (a simplification of Zorin's boundary stencils);
//  - boundary edge with boundary neighbours p (before a) and q (after b): the four-point rule
//    9/16(a+b) − 1/16(p+q); midpoint when the boundary is not a simple chain there;
//  - non-manifold edge (> 2 faces): midpoint.
// Child faces of input face f = (v0, v1, v2) with edge vertices m01, m12, m20 are rows
// 4f..4f+3: (v0, m01, m20), (v1, m12, m01), (v2, m20, m12), (m01, m12, m20), so the coarse faces
// can be read back from the fine ones (butterfly_coarsen), orientation kept.
#pragma once

#include <Eigen/Core>

namespace mm {

struct ButterflyResult {
  Eigen::MatrixXd V;  // #V + #E by 3 (input vertices first, unchanged)
  Eigen::MatrixXi F;  // 4·#F by 3, child order as in the header
  int coarse_vertices = 0;  // #V of the input
};

// One level. V: #V by 3, F: #F by 3 (any triangle mesh; open boundaries allowed).
ButterflyResult butterfly_subdivide(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// `levels` ≥ 0 levels; coarse_vertices is the #V of the input (level 0).
ButterflyResult butterfly_subdivide(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int levels);

// Exact removal of `levels` levels: V' = first `coarse_vertices` rows of V (any positions, e.g. a
// deformed fine mesh), F' read from the first corners of each group of four child faces.
// F.rows() must be a multiple of 4^levels (assert).
void butterfly_coarsen(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int levels, int coarse_vertices,
                       Eigen::MatrixXd* Vout, Eigen::MatrixXi* Fout);

}  // namespace mm
