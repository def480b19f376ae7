//! The tangent plane of the limit surface at a boundary vertex with k >= 3 faces (all quads),
//! from the eigenvectors of the local subdivision matrix.
//!
//! No closed-form mask fits the standard crease rule there: OpenSubdiv's cross-tangent mask
//! (Biermann et al.) belongs to modified rules, so the normal it gives depends on the level at
//! which it is applied. The tangent plane is spanned by the two subdominant left eigenvectors of
//! the matrix S that maps the ring (v, e_0..e_k, f_0..f_{k-1}) to the same ring one level finer:
//! along the boundary `e_0 - e_k` (eigenvalue 1/2), across it the other one. Subspace iteration
//! on S^T, with the limit-position mask (eigenvalue 1) projected out, converges to their span.

use glam::DVec3;

/// Two vectors spanning the limit tangent plane at boundary vertex `v` with edge neighbours
/// `edges` (k + 1, counter-clockwise from the leading boundary edge) and face-diagonal
/// neighbours `diagonals` (k).
pub(crate) fn boundary_tangent_plane(
    v: DVec3,
    edges: &[DVec3],
    diagonals: &[DVec3],
) -> (DVec3, DVec3) {
    let k = diagonals.len();
    debug_assert_eq!(edges.len(), k + 1);
    let s = subdivision_matrix(k);
    let m = s.len();
    // The limit-position mask: (e_0 + 4 v + e_k) / 6; removing x·1 times it removes the
    // eigenvalue-1 component of a left vector x (every other left eigenvector sums to 0).
    let mut limit = vec![0.0; m];
    limit[0] = 4.0 / 6.0;
    limit[1] = 1.0 / 6.0;
    limit[k + 1] = 1.0 / 6.0;
    let project = |x: &mut [f64]| {
        let sum: f64 = x.iter().sum();
        for (xi, li) in x.iter_mut().zip(&limit) {
            *xi -= sum * li;
        }
    };
    // Two start vectors with components in every direction.
    let mut basis: [Vec<f64>; 2] = [
        (0..m).map(|i| 1.0 + (i as f64 * 0.731).sin()).collect(),
        (0..m).map(|i| (i as f64 * 1.913 + 0.3).cos()).collect(),
    ];
    // The slowest ratio of eigenvalues seen on the shared meshes is about 0.82 per step.
    for _ in 0..400 {
        for x in basis.iter_mut() {
            let mut y = vec![0.0; m];
            for (i, row) in s.iter().enumerate() {
                for (j, &w) in row.iter().enumerate() {
                    y[j] += x[i] * w;
                }
            }
            project(&mut y);
            *x = y;
        }
        orthonormalize(&mut basis);
    }
    let ring: Vec<DVec3> = std::iter::once(v)
        .chain(edges.iter().copied())
        .chain(diagonals.iter().copied())
        .collect();
    let apply = |w: &[f64]| w.iter().zip(&ring).map(|(&a, &p)| a * p).sum::<DVec3>();
    (apply(&basis[0]), apply(&basis[1]))
}

fn orthonormalize(basis: &mut [Vec<f64>; 2]) {
    let norm = |x: &[f64]| x.iter().map(|a| a * a).sum::<f64>().sqrt();
    let n0 = norm(&basis[0]);
    basis[0].iter_mut().for_each(|a| *a /= n0);
    let dot: f64 = basis[0].iter().zip(&basis[1]).map(|(a, b)| a * b).sum();
    let [first, second] = basis;
    for (b, a) in second.iter_mut().zip(first.iter()) {
        *b -= dot * a;
    }
    let n1 = norm(second);
    second.iter_mut().for_each(|a| *a /= n1);
}

/// Rows: new points (v', e'_0..e'_k, F_0..F_{k-1}) as combinations of the old ring, with the
/// crease rule on the boundary edges and Catmull-Clark inside.
fn subdivision_matrix(k: usize) -> Vec<Vec<f64>> {
    let m = 2 * k + 2;
    let (v, e, f) = (0, |i: usize| 1 + i, |i: usize| k + 2 + i);
    let face_point = |i: usize| {
        let mut row = vec![0.0; m];
        for idx in [v, e(i), f(i), e(i + 1)] {
            row[idx] += 0.25;
        }
        row
    };
    let mut s = vec![vec![0.0; m]; m];
    s[v][v] = 6.0 / 8.0;
    s[v][e(0)] = 1.0 / 8.0;
    s[v][e(k)] = 1.0 / 8.0;
    for (i, end) in [(0, e(0)), (k, e(k))] {
        s[e(i)][v] = 0.5;
        s[e(i)][end] += 0.5;
    }
    for i in 1..k {
        let (before, after) = (face_point(i - 1), face_point(i));
        for j in 0..m {
            s[e(i)][j] = 0.25 * (before[j] + after[j]);
        }
        s[e(i)][v] += 0.25;
        s[e(i)][e(i)] += 0.25;
    }
    for i in 0..k {
        s[f(i)] = face_point(i);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_boundary_fan_has_the_plane_as_tangent_plane() {
        // k = 4 faces in the half plane y > 0 of z = 0, bent nowhere: the tangent plane is z = 0.
        let angle = |i: usize| std::f64::consts::PI * i as f64 / 4.0;
        let edges: Vec<DVec3> = (0..=4)
            .map(|i| DVec3::new(angle(i).cos(), angle(i).sin(), 0.0))
            .collect();
        let diagonals: Vec<DVec3> = (0..4)
            .map(|i| 1.3 * DVec3::new((angle(i) + 0.39).cos(), (angle(i) + 0.39).sin(), 0.0))
            .collect();
        let (a, b) = boundary_tangent_plane(DVec3::ZERO, &edges, &diagonals);
        let n = a.cross(b).normalize();
        assert!(n.z.abs() > 1.0 - 1e-12, "{n}");
    }
}
