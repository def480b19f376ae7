//! Values grouped by a small integer key in linear time (a counting sort), in the order they
//! were given: edges by their lower vertex, corners by their vertex.

use crate::huge_pages::vec_to_fill;

/// The values `each` gives, grouped by key (`keys` of them): key `k`'s values are
/// `values[starts[k]..starts[k + 1]]`, in the order given. `each` is called twice, and must
/// give the same values both times.
pub fn group_by_key<T: Copy + Default>(
    keys: usize,
    each: impl Fn(&mut dyn FnMut(u32, T)),
) -> (Vec<usize>, Vec<T>) {
    let mut starts = vec![0usize; keys + 1];
    each(&mut |key, _| starts[key as usize + 1] += 1);
    for k in 0..keys {
        starts[k + 1] += starts[k];
    }
    let mut fill = starts.clone();
    let mut values = vec_to_fill(starts[keys]);
    values.resize(starts[keys], T::default());
    each(&mut |key, value| {
        values[fill[key as usize]] = value;
        fill[key as usize] += 1;
    });
    (starts, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_grouped_in_the_order_given() {
        let pairs = [(2u32, 'a'), (0, 'b'), (2, 'c'), (0, 'd'), (3, 'e')];
        let (starts, values) =
            group_by_key(4, |visit| pairs.iter().for_each(|&(k, v)| visit(k, v)));
        assert_eq!(starts, vec![0, 2, 2, 4, 5]);
        assert_eq!(values, vec!['b', 'd', 'a', 'c', 'e']);
    }
}
