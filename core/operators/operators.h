// Discrete differential operators on a triangle mesh (conventions of mesh/mesh.h).
//
// Laplacian sign convention (owned here): the cotangent stiffness W is POSITIVE
// SEMI-DEFINITE, W·1 = 0, with off-diagonals W_ij = -½(cot α_ij + cot β_ij) and
// W_ii = -Σ_j W_ij. Paper 000 Eq. 1 writes the opposite sign (w_ij = +½(cot+cot),
// negative diagonal); our W is its negation, so Wφ = λAφ has λ ≥ 0 ascending.
// The continuous Laplace–Beltrami operator is Δ ≈ -A⁻¹W.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace mm {

using SparseMatrix = Eigen::SparseMatrix<double>;

// Cotangent stiffness matrix W (#V by #V), positive semi-definite. Each triangle adds
// ½cot of its angle to the opposite edge. Degenerate triangles (zero area) contribute nothing
// rather than Inf; so do faces with an index outside V.
SparseMatrix cotan_stiffness(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

enum class MassType {
  Voronoi,     // mixed Voronoi areas (Meyer et al. 2003): Voronoi for non-obtuse triangles,
               // area/2 to the obtuse corner and area/4 to the others otherwise
  Barycentric, // one third of each incident triangle's area
};

// Lumped (diagonal) mass: #V vector of vertex areas. Sums to the surface area.
Eigen::VectorXd mass_diagonal(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                              MassType type = MassType::Voronoi);

// The same as a sparse diagonal matrix A.
SparseMatrix mass_matrix(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                         MassType type = MassType::Voronoi);

// Uniform (graph) Laplacian, positive semi-definite: L_ij = -1 for neighbours, L_ii = degree.
SparseMatrix uniform_laplacian(const Eigen::MatrixXi& F, int num_vertices);

// Per-face unit normals (#F by 3); zero rows for degenerate faces.
Eigen::MatrixXd face_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// Per-vertex unit normals (#V by 3), area-weighted average of incident face normals.
// Vertices with no non-degenerate incident face get a zero row.
// = grouped_vertex_normals(V, F, F, #V).
Eigen::MatrixXd vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// Area-weighted unit normals of groups of face corners (#groups by 3): corner k of face f adds
// the face's area vector (b − a) × (c − a) to group G(f, k) (G: #F by 3, e.g. vertices welded
// across seams, or normal indices of an OBJ). Faces with an out-of-range index or a non-finite
// area vector and corners with an out-of-range group are skipped; empty groups get a zero row.
Eigen::MatrixXd grouped_vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXi& G,
                                       int num_groups);

// Per-face areas (#F).
Eigen::VectorXd face_areas(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

}  // namespace mm
