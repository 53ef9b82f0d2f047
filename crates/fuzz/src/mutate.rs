//! A deterministic random source and the mutations: byte flips, random bytes, insertions,
//! deletions, duplicated and spliced ranges, truncations, and (for text) numbers replaced by
//! extreme values.

/// SplitMix64: small, fast, and the same sequence on every machine.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// The generator of input `index` of a campaign with `seed` (inputs are independent, so
    /// any one can be regenerated alone).
    pub fn for_input(seed: u64, index: u64) -> Self {
        let mut r = Rng(seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        r.next_u64();
        r
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// One element of `v` (non-empty).
    pub fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

/// Extreme values that replace numbers in text inputs.
pub const EXTREMES: &[&str] = &[
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "0",
    "-0",
    "-0.0",
    "0.0",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e400",
    "-1",
    "1e-15",
    "1e15",
    "2147483648",
    "4294967296",
    "9223372036854775807",
    "18446744073709551616",
    "-9223372036854775809",
    "99999999999999999999999",
    "1e7",
    "10000000",
];

/// Extreme `f64` bit patterns that replace 8-byte fields of binary inputs.
pub const EXTREME_F64: &[f64] = &[
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e308,
    -1e308,
    -0.0,
    5e-324,
    f64::MAX,
    f64::MIN_POSITIVE,
];

/// One generic byte mutation of `b`; `others` are inputs to splice from.
pub fn mutate_bytes(r: &mut Rng, b: &mut Vec<u8>, others: &[Vec<u8>]) {
    let n = b.len();
    match r.below(9) {
        0 | 1 if n > 0 => {
            let i = r.below(n);
            b[i] ^= 1 << r.below(8);
        }
        2 if n > 0 => {
            let i = r.below(n);
            b[i] = r.next_u64() as u8;
        }
        3 => {
            let i = r.below(n + 1);
            let k = 1 + r.below(8);
            for _ in 0..k {
                b.insert(i, r.next_u64() as u8);
            }
        }
        4 if n > 0 => {
            let i = r.below(n);
            let k = (1 + r.below(64)).min(n - i);
            b.drain(i..i + k);
        }
        5 if n > 0 => {
            // Duplicate a range in place.
            let i = r.below(n);
            let k = (1 + r.below(256)).min(n - i);
            let piece: Vec<u8> = b[i..i + k].to_vec();
            let at = r.below(n + 1);
            b.splice(at..at, piece);
        }
        6 if !others.is_empty() => {
            // Splice a range of another input.
            let o = r.pick(others);
            if !o.is_empty() {
                let i = r.below(o.len());
                let k = (1 + r.below(256)).min(o.len() - i);
                let at = r.below(n + 1);
                let end = (at + r.below(k + 1)).min(n);
                b.splice(at..end, o[i..i + k].iter().copied());
            }
        }
        7 if n > 0 => {
            b.truncate(r.below(n));
        }
        _ if n >= 8 => {
            // An extreme f64 over 8 bytes.
            let i = r.below(n - 7);
            let v = *r.pick(EXTREME_F64);
            b[i..i + 8].copy_from_slice(&v.to_le_bytes());
        }
        _ => b.push(r.next_u64() as u8),
    }
}

/// Byte ranges of the numbers in `t` (digits with sign, point, exponent).
pub fn numbers(t: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let starts = t[i].is_ascii_digit()
            || ((t[i] == b'-' || t[i] == b'+' || t[i] == b'.')
                && t.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (t[i - 1].is_ascii_alphanumeric() || t[i - 1] == b'_');
        if starts && !after_word {
            let s = i;
            i += 1;
            while i < t.len()
                && (t[i].is_ascii_digit()
                    || t[i] == b'.'
                    || t[i] == b'e'
                    || t[i] == b'E'
                    || ((t[i] == b'-' || t[i] == b'+') && matches!(t[i - 1], b'e' | b'E')))
            {
                i += 1;
            }
            v.push((s, i));
        } else {
            i += 1;
        }
    }
    v
}

/// One text mutation (numbers replaced by extremes, lines deleted or repeated, array elements
/// added), or a byte mutation.
pub fn mutate_text(r: &mut Rng, b: &mut Vec<u8>, others: &[Vec<u8>]) {
    match r.below(10) {
        0..=4 => {
            let nums = numbers(b);
            if nums.is_empty() {
                return mutate_bytes(r, b, others);
            }
            let (s, e) = *r.pick(&nums);
            let x = r.pick(EXTREMES);
            b.splice(s..e, x.bytes());
        }
        5 => {
            // Repeat a line (a table or key given twice).
            let lines = line_ranges(b);
            if let Some(&(s, e)) = (!lines.is_empty()).then(|| r.pick(&lines)) {
                let piece = b[s..e].to_vec();
                b.splice(e..e, piece);
            }
        }
        6 => {
            // Delete a line.
            let lines = line_ranges(b);
            if let Some(&(s, e)) = (!lines.is_empty()).then(|| r.pick(&lines)) {
                b.drain(s..e);
            }
        }
        7 => {
            // One more element in an array: `]` → `, 1.0]`.
            let closes: Vec<usize> = (0..b.len()).filter(|&i| b[i] == b']').collect();
            if !closes.is_empty() {
                let i = *r.pick(&closes);
                let x = format!(", {}", r.pick(EXTREMES));
                b.splice(i..i, x.bytes());
            }
        }
        _ => mutate_bytes(r, b, others),
    }
}

fn line_ranges(b: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut s = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            v.push((s, i + 1));
            s = i + 1;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_found_but_not_inside_names() {
        let t = b"x_2 = -1.5e-3\nname = 'a1'\nv = [1, 2]";
        let got: Vec<&[u8]> = numbers(t).iter().map(|&(s, e)| &t[s..e]).collect();
        assert_eq!(got, vec![&b"-1.5e-3"[..], b"1", b"2"]);
    }

    #[test]
    fn inputs_are_reproducible_one_by_one() {
        let a: Vec<u64> = (0..3).map(|_| Rng::for_input(7, 41).next_u64()).collect();
        assert_eq!(a[0], a[1]);
        assert_ne!(
            Rng::for_input(7, 41).next_u64(),
            Rng::for_input(7, 42).next_u64()
        );
    }
}
