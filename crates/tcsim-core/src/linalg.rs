//! Small dense linear algebra for the engines' reduced mass matrices.

/// Inverse of a small dense matrix (Gauss–Jordan, partial pivoting).
pub fn invert(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let mut m = a.to_vec();
    let mut inv: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
    gauss_jordan(&mut m, &mut inv)?;
    Some(inv)
}

/// Inverse of the leading `n`×`n` block of `a` (the rest zero), without allocating: [`invert`]'s
/// arithmetic, bit for bit, on the engines' 4×4 mass matrices.
pub fn invert_leading(n: usize, a: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let mut m = [[0.0; 4]; 4];
    let mut inv = [[0.0; 4]; 4];
    for i in 0..n {
        m[i][..n].copy_from_slice(&a[i][..n]);
        inv[i][i] = 1.0;
    }
    gauss_jordan(&mut m[..n], &mut inv[..n])?;
    Some(inv)
}

/// Reduce `m` (rows of the matrix's n columns and perhaps more, zero) to the identity and apply
/// the same row operations to `inv` (the identity at the start); None for a singular `m`.
fn gauss_jordan<R: AsMut<[f64]> + AsRef<[f64]>>(m: &mut [R], inv: &mut [R]) -> Option<()> {
    let n = m.len();
    let at = |rows: &[R], r: usize, c: usize| rows[r].as_ref()[c];
    for col in 0..n {
        let p = (col..n).max_by(|&i, &j| at(m, i, col).abs().total_cmp(&at(m, j, col).abs()))?;
        if at(m, p, col) == 0.0 || !at(m, p, col).is_finite() {
            return None;
        }
        m.swap(col, p);
        inv.swap(col, p);
        let d = at(m, col, col);
        for k in 0..n {
            m[col].as_mut()[k] /= d;
            inv[col].as_mut()[k] /= d;
        }
        for r in 0..n {
            if r != col {
                let f = at(m, r, col);
                if f != 0.0 {
                    for k in 0..n {
                        let (mk, ik) = (at(m, col, k), at(inv, col, k));
                        m[r].as_mut()[k] -= f * mk;
                        inv[r].as_mut()[k] -= f * ik;
                    }
                }
            }
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic spread of values (no random crate in the core's tests).
    fn value(i: usize) -> f64 {
        ((i as f64 * 0.618_033_988_749_895).fract() - 0.5) * 10f64.powi((i % 7) as i32 - 3)
    }

    #[test]
    fn the_leading_block_inverse_is_the_inverse_of_the_block_bit_for_bit() {
        // the engines invert their mass matrices with `invert_leading` (no allocation); it must be
        // `invert` of the same block to the bit, singular blocks refused alike, and an inverse
        let mut seen = [0usize; 2];
        for case in 0..400 {
            let n = 1 + case % 4;
            let mut a = [[f64::NAN; 4]; 4]; // what lies outside the block is never read
            for (r, row) in a.iter_mut().enumerate().take(n) {
                for (c, x) in row.iter_mut().enumerate().take(n) {
                    *x = value(case * 16 + r * 4 + c);
                }
            }
            if case % 5 == 0 && n > 1 {
                a[n - 1] = a[0]; // singular: a repeated row
                a[n - 1][n..].fill(f64::NAN);
            }
            if case % 11 == 0 {
                a[0][0] = 0.0; // a zero pivot candidate: partial pivoting swaps rows
            }
            let block: Vec<Vec<f64>> = (0..n).map(|r| a[r][..n].to_vec()).collect();
            let (fixed, general) = (invert_leading(n, &a), invert(&block));
            assert_eq!(fixed.is_some(), general.is_some(), "case {case}");
            let (Some(fixed), Some(general)) = (fixed, general) else {
                seen[0] += 1;
                continue;
            };
            seen[1] += 1;
            for r in 0..4 {
                for c in 0..4 {
                    let want = if r < n && c < n { general[r][c].to_bits() } else { 0f64.to_bits() };
                    assert_eq!(fixed[r][c].to_bits(), want, "case {case} ({r}, {c})");
                }
            }
            for (r, row) in block.iter().enumerate() {
                for c in 0..n {
                    let terms = || row.iter().zip(&general).map(|(a, inv)| a * inv[c]);
                    let (product, scale) = (terms().sum::<f64>(), terms().map(f64::abs).sum::<f64>());
                    let expected = if r == c { 1.0 } else { 0.0 };
                    assert!((product - expected).abs() <= 1e-9 * scale.max(1.0), "case {case}: A·A⁻¹ ({r}, {c})");
                }
            }
        }
        assert!(seen[0] >= 50 && seen[1] >= 200, "singular and regular cases both met: {seen:?}");
    }
}
