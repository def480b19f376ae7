//! A mesh's shells: its faces grouped by the vertices they share (union-find over vertex
//! indices), each shell a connected piece of surface.

use super::Mesh;

/// The faces of each shell, in face order.
pub fn shells(mesh: &Mesh) -> Vec<Vec<u32>> {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            let up = parent[parent[v as usize] as usize];
            parent[v as usize] = up;
            v = up;
        }
        v
    }
    for f in 0..mesh.face_count() {
        let face = mesh.face(f);
        let first = root(&mut parent, face[0]);
        for &v in &face[1..] {
            let r = root(&mut parent, v);
            parent[r as usize] = first;
        }
    }
    let mut shell_of_root = vec![u32::MAX; parent.len()];
    let mut shells: Vec<Vec<u32>> = Vec::new();
    for f in 0..mesh.face_count() {
        let r = root(&mut parent, mesh.face(f)[0]) as usize;
        if shell_of_root[r] == u32::MAX {
            shell_of_root[r] = shells.len() as u32;
            shells.push(Vec::new());
        }
        shells[shell_of_root[r] as usize].push(f as u32);
    }
    shells
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;
    use glam::DVec3;

    #[test]
    fn two_cubes_are_two_shells_and_one_is_one() {
        let a = generate::cuboid(DVec3::ZERO, DVec3::ONE);
        assert_eq!(shells(&a).len(), 1);
        let b = generate::cuboid(DVec3::splat(2.0), DVec3::splat(3.0));
        let both = generate::combine("two cubes", &[a.clone(), b]);
        let found = shells(&both);
        assert_eq!(found.len(), 2);
        assert_eq!(found[0].len(), a.face_count());
    }
}
