//! Vectors made of parts one after another, the parts moved into place on all threads. A
//! large result is megabytes of fresh memory, whose pages cost more to make than the copy: on
//! one thread that kept the other waiting (igea: the level set's 79,000 band leaves, 9 MB; its
//! OBJ file's vertices and corners, 8 MB).

use crate::huge_pages::vec_to_fill;
use rayon::prelude::*;

/// `parts` one after another.
pub fn concat<T: Send>(parts: Vec<Vec<T>>) -> Vec<T> {
    concat_with(parts, |_, v| v)
}

/// `parts` one after another, each value passed through `map` with its part's number.
pub fn concat_with<T: Send>(parts: Vec<Vec<T>>, map: impl Fn(usize, T) -> T + Sync) -> Vec<T> {
    let total = parts.iter().map(Vec::len).sum();
    let mut out = vec_to_fill(total);
    let mut rest = &mut out.spare_capacity_mut()[..total];
    let places: Vec<_> = parts
        .iter()
        .map(|part| {
            let (place, after) = std::mem::take(&mut rest).split_at_mut(part.len());
            rest = after;
            place
        })
        .collect();
    places
        .into_par_iter()
        .zip(parts)
        .enumerate()
        .for_each(|(k, (place, part))| {
            for (slot, value) in place.iter_mut().zip(part) {
                slot.write(map(k, value));
            }
        });
    // SAFETY: the places are the first `total` of the capacity, each written once above.
    unsafe { out.set_len(total) };
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_come_one_after_another_each_mapped_with_its_number() {
        let parts = vec![vec![1, 2], vec![], vec![3], vec![4, 5, 6]];
        assert_eq!(concat(parts.clone()), vec![1, 2, 3, 4, 5, 6]);
        assert_eq!(
            concat_with(parts, |k, v| v + 10 * k as i32),
            vec![1, 2, 23, 34, 35, 36]
        );
        let owned = vec![vec![String::from("a")], vec![String::from("b")]];
        assert_eq!(concat(owned), vec!["a", "b"]);
    }
}
