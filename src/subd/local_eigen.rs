//! The limit position and tangent plane at a vertex where no closed-form mask fits, from the
//! eigenvectors of the local subdivision matrix S that maps the vertex's ring to the same
//! ring one level finer (all faces quads):
//! - a crease or boundary vertex with k >= 2 faces on one side, ring (v, e_0..e_k, f_0..f_{k-1})
//!   between the sharp edges e_0 and e_k: the crease rule (e_0 + 6 v + e_k) / 8 and midpoints
//!   along them, Catmull-Clark inside. OpenSubdiv's cross-tangent mask (Biermann et al.) belongs
//!   to modified rules, so the normal it gives depends on the level at which it is applied.
//! - a dart, an interior vertex of n faces whose one sharp edge e_0 ends there, ring
//!   (v, e_0..e_{n-1}, f_0..f_{n-1}): the smooth rule at v, the midpoint on e_0. The smooth
//!   masks, which OpenSubdiv's `Limit()` applies there, are not its limit.
//!
//! The limit position is the left eigenvector of eigenvalue 1 (power iteration on S^T); the
//! tangent plane is spanned by the two subdominant left eigenvectors (subspace iteration on S^T
//! with the eigenvalue-1 component projected out: every other left eigenvector sums to 0).

use glam::DVec3;

/// The limit position and two vectors spanning the tangent plane at crease vertex `v` with
/// edge neighbours `edges` (k + 1, counter-clockwise from the leading sharp edge) and
/// face-diagonal neighbours `diagonals` (k).
pub(crate) fn crease_limit(v: DVec3, edges: &[DVec3], diagonals: &[DVec3]) -> Limit {
    let k = diagonals.len();
    debug_assert_eq!(edges.len(), k + 1);
    let mut s = ring_matrix(k, false);
    let (v_, e) = (0, |i: usize| 1 + i);
    s[v_][v_] = 6.0 / 8.0;
    s[v_][e(0)] = 1.0 / 8.0;
    s[v_][e(k)] = 1.0 / 8.0;
    for end in [e(0), e(k)] {
        s[end] = vec![0.0; s.len()];
        s[end][v_] = 0.5;
        s[end][end] = 0.5;
    }
    // The crease curve's own mask, (e_0 + 4 v + e_k) / 6, is exact.
    let mut position = vec![0.0; s.len()];
    position[v_] = 4.0 / 6.0;
    position[e(0)] = 1.0 / 6.0;
    position[e(k)] = 1.0 / 6.0;
    eigen_limit(&s, position, &ring_points(v, edges, diagonals))
}

/// The limit at dart `v` with edge neighbours `edges` (n, counter-clockwise from the sharp
/// edge) and face-diagonal neighbours `diagonals` (n).
pub(crate) fn dart_limit(v: DVec3, edges: &[DVec3], diagonals: &[DVec3]) -> Limit {
    let n = diagonals.len();
    debug_assert_eq!(edges.len(), n);
    let mut s = ring_matrix(n, true);
    let m = s.len();
    let (v_, e) = (0, |i: usize| 1 + i);
    // The smooth vertex rule: ((n - 2) v + (Σ e_i + Σ F_i) / n) / n with F_i the face points.
    let nf = n as f64;
    s[v_] = vec![0.0; m];
    s[v_][v_] = (nf - 2.0) / nf;
    for i in 0..n {
        s[v_][e(i)] += 1.0 / (nf * nf);
        for (idx, w) in face_point(n, true, i) {
            s[v_][idx] += w / (nf * nf);
        }
    }
    s[e(0)] = vec![0.0; m];
    s[e(0)][v_] = 0.5;
    s[e(0)][e(0)] = 0.5;
    // Power iteration on S^T from the smooth mask converges to the limit-position mask.
    let mut position = vec![0.0; m];
    position[v_] = 1.0;
    for _ in 0..POWER_STEPS {
        position = left_multiply(&position, &s);
        let sum: f64 = position.iter().sum();
        position.iter_mut().for_each(|a| *a /= sum);
    }
    eigen_limit(&s, position, &ring_points(v, edges, diagonals))
}

/// A vertex's limit position and two vectors spanning its tangent plane (unoriented).
pub(crate) struct Limit {
    pub position: DVec3,
    pub tangents: (DVec3, DVec3),
}

/// Iterations of the power and subspace iterations: the slowest ratio of eigenvalues seen on
/// the shared meshes is about 0.82 per step.
const POWER_STEPS: usize = 400;

fn ring_points(v: DVec3, edges: &[DVec3], diagonals: &[DVec3]) -> Vec<DVec3> {
    std::iter::once(v)
        .chain(edges.iter().copied())
        .chain(diagonals.iter().copied())
        .collect()
}

fn left_multiply(x: &[f64], s: &[Vec<f64>]) -> Vec<f64> {
    let mut y = vec![0.0; x.len()];
    for (i, row) in s.iter().enumerate() {
        for (j, &w) in row.iter().enumerate() {
            y[j] += x[i] * w;
        }
    }
    y
}

/// The limit of the ring under `s`, whose limit-position mask is `position` (summing to 1).
fn eigen_limit(s: &[Vec<f64>], position: Vec<f64>, ring: &[DVec3]) -> Limit {
    let m = s.len();
    let project = |x: &mut [f64]| {
        let sum: f64 = x.iter().sum();
        for (xi, li) in x.iter_mut().zip(&position) {
            *xi -= sum * li;
        }
    };
    // Two start vectors with components in every direction.
    let mut basis: [Vec<f64>; 2] = [
        (0..m).map(|i| 1.0 + (i as f64 * 0.731).sin()).collect(),
        (0..m).map(|i| (i as f64 * 1.913 + 0.3).cos()).collect(),
    ];
    for _ in 0..POWER_STEPS {
        for x in basis.iter_mut() {
            let mut y = left_multiply(x, s);
            project(&mut y);
            *x = y;
        }
        orthonormalize(&mut basis);
    }
    let apply = |w: &[f64]| w.iter().zip(ring).map(|(&a, &p)| a * p).sum::<DVec3>();
    Limit {
        position: apply(&position),
        tangents: (apply(&basis[0]), apply(&basis[1])),
    }
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

/// Face point i of a ring of `faces` quads, as (ring index, weight): face i has corners v,
/// e_i, f_i and e_{i+1} (e_0 again after the last face of a closed ring).
fn face_point(faces: usize, closed: bool, i: usize) -> [(usize, f64); 4] {
    let edges = if closed { faces } else { faces + 1 };
    let e = |j: usize| 1 + j % edges;
    [
        (0, 0.25),
        (e(i), 0.25),
        (edges + 1 + i, 0.25),
        (e(i + 1), 0.25),
    ]
}

/// The Catmull-Clark rows of a ring of `faces` quads around v (closed: every edge between two
/// faces; open: e_0 and e_faces on one face only, their rows left for the caller), the vertex's
/// own row left for the caller. Rows: new points (v', e'_i, F_i) as combinations of the old
/// ring (v, e_i, f_i).
fn ring_matrix(faces: usize, closed: bool) -> Vec<Vec<f64>> {
    let edges = if closed { faces } else { faces + 1 };
    let m = 1 + edges + faces;
    let mut s = vec![vec![0.0; m]; m];
    for i in 0..faces {
        for (idx, w) in face_point(faces, closed, i) {
            s[edges + 1 + i][idx] += w;
        }
    }
    for i in 0..edges {
        let (before, after) = match (i, closed) {
            (0, true) => (faces - 1, 0),
            (i, _) if i == 0 || i == faces => continue,
            (i, _) => (i - 1, i),
        };
        s[1 + i][0] += 0.25;
        s[1 + i][1 + i] += 0.25;
        for face in [before, after] {
            for (idx, w) in face_point(faces, closed, face) {
                s[1 + i][idx] += 0.25 * w;
            }
        }
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
        let limit = crease_limit(DVec3::ZERO, &edges, &diagonals);
        let n = limit.tangents.0.cross(limit.tangents.1).normalize();
        assert!(n.z.abs() > 1.0 - 1e-12, "{n}");
        assert!((limit.position - (edges[0] + edges[4]) / 6.0).length() < 1e-15);
    }

    #[test]
    fn a_flat_dart_fan_has_its_limit_in_the_plane() {
        // n = 5 faces around a dart at the origin in z = 0, the sharp edge along +x.
        let angle = |i: usize| std::f64::consts::TAU * i as f64 / 5.0;
        let edges: Vec<DVec3> = (0..5)
            .map(|i| (1.0 + 0.1 * i as f64) * DVec3::new(angle(i).cos(), angle(i).sin(), 0.0))
            .collect();
        let diagonals: Vec<DVec3> = (0..5)
            .map(|i| 1.4 * DVec3::new((angle(i) + 0.6).cos(), (angle(i) + 0.6).sin(), 0.0))
            .collect();
        let limit = dart_limit(DVec3::ZERO, &edges, &diagonals);
        let n = limit.tangents.0.cross(limit.tangents.1).normalize();
        assert!(n.z.abs() > 1.0 - 1e-12, "{n}");
        assert!(limit.position.z.abs() < 1e-15);
        // Not the smooth mask's point: the sharp edge pulls the limit towards e_0.
        let nf = 5.0;
        let smooth = (edges.iter().sum::<DVec3>() * 4.0 + diagonals.iter().sum::<DVec3>())
            / (nf * (nf + 5.0));
        assert!(
            (limit.position - smooth).length() > 1e-3,
            "{:?} {smooth:?}",
            limit.position
        );
    }
}
