//! Weighted empirical quantile functions (inverse cumulative distribution functions),
//! sampled at `Q` evenly spaced probabilities `p_m = (m + ½) / Q`.
//!
//! They are the histogram representation of the parametric transfer engine (paper B
//! §5.2, after Heeger & Bergen 1995 and Matusik, Zwicker & Durand 2005): matching a value
//! `v` from distribution `T` to distribution `S` is `S⁻¹(T(v))`, and distributions are
//! blended by averaging their quantile functions, which moves mass instead of mixing
//! histograms (the blend of two unimodal distributions stays unimodal).

/// A quantile function sampled at `Q` probabilities (module docs); `values` are
/// non-decreasing.
#[derive(Debug, Clone, PartialEq)]
pub struct QuantileFunction {
    pub values: Vec<f64>,
}

impl QuantileFunction {
    /// The quantile function of `values` with non-negative `weights` (same length) at
    /// `q ≥ 1` probabilities. Each sample stands for the probability interval of its
    /// weight; the quantile at `p` interpolates linearly between the midpoints of the
    /// neighbouring samples' intervals. `None` when the total weight is not positive.
    /// Non-finite values or weights are skipped.
    pub fn from_weighted(values: &[f64], weights: &[f64], q: usize) -> Option<Self> {
        let mut pairs: Vec<(f64, f64)> = values
            .iter()
            .zip(weights)
            .filter(|(v, w)| v.is_finite() && w.is_finite() && **w > 0.0)
            .map(|(&v, &w)| (v, w))
            .collect();
        Self::from_pairs(&mut pairs, q)
    }

    /// The quantile function of unweighted `values`.
    pub fn from_samples(values: &[f64], q: usize) -> Option<Self> {
        let mut pairs: Vec<(f64, f64)> =
            values.iter().filter(|v| v.is_finite()).map(|&v| (v, 1.0)).collect();
        Self::from_pairs(&mut pairs, q)
    }

    fn from_pairs(pairs: &mut [(f64, f64)], q: usize) -> Option<Self> {
        let q = q.max(1);
        let total: f64 = pairs.iter().map(|p| p.1).sum();
        if pairs.is_empty() || total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut out = Vec::with_capacity(q);
        let mut i = 0usize;
        let mut below = 0.0; // weight strictly before sample i
        for m in 0..q {
            let p = (m as f64 + 0.5) / q as f64 * total;
            // Advance while the next sample's midpoint is at or below p.
            while i + 1 < pairs.len() && below + pairs[i].1 + 0.5 * pairs[i + 1].1 <= p {
                below += pairs[i].1;
                i += 1;
            }
            let c0 = below + 0.5 * pairs[i].1;
            let v = if p <= c0 || i + 1 >= pairs.len() {
                pairs[i].0
            } else {
                let c1 = below + pairs[i].1 + 0.5 * pairs[i + 1].1;
                let t = ((p - c0) / (c1 - c0)).clamp(0.0, 1.0);
                pairs[i].0 + t * (pairs[i + 1].0 - pairs[i].0)
            };
            out.push(v);
        }
        Some(Self { values: out })
    }

    /// Number of sampled probabilities `Q`.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The quantile at probability `p` (linear between the samples, constant beyond).
    pub fn eval(&self, p: f64) -> f64 {
        let q = self.values.len();
        let x = p * q as f64 - 0.5;
        if x <= 0.0 {
            return self.values[0];
        }
        let m = x.floor() as usize;
        if m + 1 >= q {
            return self.values[q - 1];
        }
        let t = x - m as f64;
        self.values[m] + t * (self.values[m + 1] - self.values[m])
    }

    /// The cumulative probability of `v` (the inverse of [`eval`](Self::eval); a value
    /// inside a run of equal quantiles maps to the run's middle probability).
    pub fn cdf(&self, v: f64) -> f64 {
        let q = self.values.len();
        let lo = self.values.partition_point(|&x| x < v); // first ≥ v
        let hi = self.values.partition_point(|&x| x <= v); // first > v
        if lo < hi {
            return (0.5 * (lo + hi - 1) as f64 + 0.5) / q as f64;
        }
        if lo == 0 {
            return 0.5 / q as f64;
        }
        if lo >= q {
            return (q as f64 - 0.5) / q as f64;
        }
        let (a, b) = (self.values[lo - 1], self.values[lo]);
        let t = if b > a { (v - a) / (b - a) } else { 0.5 };
        (lo as f64 - 0.5 + t) / q as f64
    }

    /// `Σ wᵢ Fᵢ⁻¹` with weights normalised to sum to one (all parts must have the same
    /// `Q`; parts with non-positive weight are skipped). `None` when nothing is left.
    pub fn mix(parts: &[(&QuantileFunction, f64)]) -> Option<Self> {
        let total: f64 = parts.iter().filter(|p| p.1 > 0.0).map(|p| p.1).sum();
        let q = parts.first()?.0.len();
        if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let mut values = vec![0.0; q];
        for (f, w) in parts.iter().filter(|p| p.1 > 0.0) {
            assert_eq!(f.len(), q, "QuantileFunction::mix: parts must share Q");
            for (v, x) in values.iter_mut().zip(&f.values) {
                *v += w / total * x;
            }
        }
        Some(Self { values })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_of_uniform_samples_and_inverse() {
        let v: Vec<f64> = (0..1000).map(|i| i as f64 / 999.0).collect();
        let f = QuantileFunction::from_samples(&v, 100).unwrap();
        for m in 0..100 {
            let p = (m as f64 + 0.5) / 100.0;
            assert!((f.values[m] - p).abs() < 2e-3, "{m}: {}", f.values[m]);
        }
        for &x in &[0.1, 0.37, 0.8] {
            assert!((f.eval(f.cdf(x)) - x).abs() < 1e-9);
        }
        // Weights: doubling the weight of the upper half moves the median up.
        let w: Vec<f64> = v.iter().map(|&x| if x > 0.5 { 2.0 } else { 1.0 }).collect();
        let g = QuantileFunction::from_weighted(&v, &w, 100).unwrap();
        assert!((g.eval(0.5) - 0.625).abs() < 0.01, "{}", g.eval(0.5));
        assert!(QuantileFunction::from_weighted(&v, &vec![0.0; 1000], 10).is_none());
    }

    #[test]
    fn mixing_averages_quantiles() {
        let a = QuantileFunction { values: vec![0.0, 1.0] };
        let b = QuantileFunction { values: vec![2.0, 5.0] };
        let m = QuantileFunction::mix(&[(&a, 1.0), (&b, 3.0)]).unwrap();
        assert_eq!(m.values, vec![1.5, 4.0]);
    }
}
