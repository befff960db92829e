//! Weighted quantile of `(value, weight)` pairs: the smallest value at which the
//! cumulative weight (values in ascending order) reaches `q` of the total.

/// The weighted `q`-quantile of `pairs` (sorted by value in place; ties keep their
/// order). `None` when `pairs` is empty or the total weight is not positive.
pub fn weighted_quantile(pairs: &mut [(f64, f64)], q: f64) -> Option<f64> {
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let mut acc = 0.0;
    for (v, w) in pairs.iter() {
        acc += w;
        if acc >= q * total {
            return Some(*v);
        }
    }
    pairs.last().map(|p| p.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_move_the_quantile() {
        let mut v = vec![(3.0, 1.0), (1.0, 1.0), (2.0, 1.0)];
        assert_eq!(weighted_quantile(&mut v, 0.5), Some(2.0));
        let mut v = vec![(3.0, 10.0), (1.0, 1.0), (2.0, 1.0)];
        assert_eq!(weighted_quantile(&mut v, 0.5), Some(3.0));
        assert_eq!(weighted_quantile(&mut v, 0.0), Some(1.0));
        assert_eq!(weighted_quantile(&mut [], 0.5), None);
        assert_eq!(weighted_quantile(&mut [(1.0, 0.0)], 0.5), None);
    }
}
