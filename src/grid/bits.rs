//! Bit operations on `u64` word arrays, shared by leaf masks and dense volumes.

#[inline]
pub fn get(words: &[u64], i: usize) -> bool {
    words[i >> 6] >> (i & 63) & 1 == 1
}

#[inline]
pub fn set(words: &mut [u64], i: usize) {
    words[i >> 6] |= 1 << (i & 63);
}

#[inline]
pub fn clear(words: &mut [u64], i: usize) {
    words[i >> 6] &= !(1 << (i & 63));
}

/// The `n` (at most 64) bits from bit `i` on, as the low bits of a word.
#[inline]
pub fn range(words: &[u64], i: usize, n: usize) -> u64 {
    let (w, b) = (i >> 6, i & 63);
    let mut v = words[w] >> b;
    if b + n > 64 {
        v |= words[w + 1] << (64 - b);
    }
    if n < 64 { v & ((1u64 << n) - 1) } else { v }
}

/// ORs the low bits of `bits` (at most 64, no others set) into the words from bit `i` on.
#[inline]
pub fn or_bits(words: &mut [u64], i: usize, bits: u64) {
    if bits == 0 {
        return;
    }
    let (w, b) = (i >> 6, i & 63);
    words[w] |= bits << b;
    if b > 0 && bits >> (64 - b) != 0 {
        words[w + 1] |= bits >> (64 - b);
    }
}

/// Sets bits `first..=last`.
pub fn set_range(words: &mut [u64], first: usize, last: usize) {
    let (fw, lw) = (first >> 6, last >> 6);
    let low = u64::MAX << (first & 63);
    let high = u64::MAX >> (63 - (last & 63));
    if fw == lw {
        words[fw] |= low & high;
        return;
    }
    words[fw] |= low;
    for w in &mut words[fw + 1..lw] {
        *w = u64::MAX;
    }
    words[lw] |= high;
}

/// Indices of the set bits, ascending.
pub fn ones(words: &[u64]) -> impl Iterator<Item = usize> + '_ {
    words.iter().enumerate().flat_map(|(w, &bits)| {
        let mut b = bits;
        std::iter::from_fn(move || {
            if b == 0 {
                return None;
            }
            let t = b.trailing_zeros() as usize;
            b &= b - 1;
            Some(w * 64 + t)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_match_single_bits() {
        let mut words = vec![0u64; 4];
        for (first, last) in [(3, 3), (5, 70), (60, 130), (64, 127), (0, 255)] {
            words.iter_mut().for_each(|w| *w = 0);
            set_range(&mut words, first, last);
            for i in 0..256 {
                assert_eq!(
                    get(&words, i),
                    (first..=last).contains(&i),
                    "{first}..={last} at {i}"
                );
            }
            for (i, n) in [(0, 64), (3, 8), (60, 8), (62, 64), (120, 17)] {
                let expect = (0..n)
                    .filter(|&k| get(&words, i + k))
                    .map(|k| 1u64 << k)
                    .sum::<u64>();
                assert_eq!(range(&words, i, n), expect);
            }
        }
    }
}
