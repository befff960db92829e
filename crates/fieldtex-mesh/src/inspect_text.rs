//! Human-readable text and warning list of an [`InspectReport`].

use crate::inspect::{Examples, InspectReport};
use fieldtex_core::Warning;

/// `(count, "COUNT WHAT (e.g. …)")` of an example list, for `problems`.
fn counted<T: std::fmt::Debug>(e: &Examples<T>, what: &str) -> (usize, String) {
    (e.count, format!("{} {what}{}", e.count, list(e)))
}

fn list<T: std::fmt::Debug>(e: &Examples<T>) -> String {
    if e.examples.is_empty() {
        return String::new();
    }
    let items: Vec<String> = e.examples.iter().map(|x| format!("{x:?}")).collect();
    format!(" (e.g. {})", bounded(items, e.count))
}

/// Items shown in plain-text lists; the rest are counted ("… and K more").
pub const LISTED_ITEMS: usize = 10;

/// The first [`LISTED_ITEMS`] of `items` joined by commas, then "… and K more" when
/// `total` (the full count) is larger than what is shown.
/// A coordinate with six decimals, or in scientific notation when that would print a
/// long run of digits or zeros (|x| ≥ 10⁹ or 0 < |x| < 10⁻⁴).
fn coordinate(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&x.abs()) {
        format!("{x:.6}")
    } else {
        format!("{x:.6e}")
    }
}

fn bounded(mut items: Vec<String>, total: usize) -> String {
    items.truncate(LISTED_ITEMS);
    let shown = items.len();
    let mut s = items.join(", ");
    if total > shown {
        s.push_str(&format!(", … and {} more", total - shown));
    }
    s
}

impl InspectReport {
    /// The problems found, as warnings with stable codes, most severe first. Several
    /// components or boundary loops are not problems and are not listed.
    pub fn problems(&self) -> Vec<Warning> {
        let mut w = Vec::new();
        let mut add = |code: &str, count: usize, what: String| {
            if count > 0 {
                w.push(Warning::new(code, what));
            }
        };
        add("empty-mesh", usize::from(self.n_triangles == 0), "the mesh has no triangles".into());
        let (n, what) = counted(&self.non_finite_vertices, "vertices with NaN/Inf coordinates");
        add("non-finite-positions", n, what);
        let (n, what) =
            counted(&self.invalid_index_triangles, "triangles refer to missing vertices");
        add("invalid-indices", n, what);
        let (n, what) = counted(&self.repeated_index_triangles, "triangles repeat a vertex");
        add("repeated-index-triangles", n, what);
        let e = &self.non_manifold_edges;
        let ex: Vec<String> = e
            .examples
            .iter()
            .map(|x| {
                let t: Vec<String> = x.triangles.iter().map(|t| t.to_string()).collect();
                format!("{:?}→[{}]", x.vertices, bounded(t, x.triangles.len()))
            })
            .collect();
        add(
            "non-manifold-edges",
            e.count,
            format!(
                "{} edges shared by more than two triangles ({})",
                e.count,
                bounded(ex, e.count)
            ),
        );
        let e = &self.non_manifold_vertices;
        let ex: Vec<String> =
            e.examples.iter().map(|x| format!("{} ({} fans)", x.vertex, x.fans)).collect();
        add(
            "non-manifold-vertices",
            e.count,
            format!(
                "{} vertices joining separate fans of triangles ({})",
                e.count,
                bounded(ex, e.count)
            ),
        );
        let (n, what) = counted(
            &self.orientation.inconsistent_edges,
            "edges where neighbouring triangles disagree in orientation",
        );
        add("inconsistent-orientation", n, what);
        let n = &self.orientation.non_orientable_components;
        add(
            "non-orientable",
            n.len(),
            format!(
                "{} non-orientable components (Möbius-like): {}",
                n.len(),
                bounded(n.iter().map(|c| c.to_string()).collect(), n.len())
            ),
        );
        let s = &self.shape;
        add(
            "zero-area-triangles",
            s.zero_area.count,
            format!(
                "{} triangles with area ≤ {:.3e}{}",
                s.zero_area.count,
                s.zero_area_tolerance,
                list(&s.zero_area)
            ),
        );
        add(
            "sliver-triangles",
            s.slivers.count,
            format!(
                "{} triangles with an angle below {}°{}",
                s.slivers.count,
                s.sliver_threshold_deg,
                list(&s.slivers)
            ),
        );
        let (n, what) = counted(&self.duplicate_triangles, "triangles repeat an earlier one");
        add("duplicate-triangles", n, what);
        let d = &self.duplicate_vertices;
        let close = d.near.saturating_sub(d.exact);
        add(
            "duplicate-vertices",
            d.weldable + close,
            format!(
                "{} vertices sit exactly on another one that they could be welded to, {close} \
                 more within {:.3e} of another ({} exact duplicates in all, including copies \
                 kept apart in separate fans)",
                d.weldable, d.epsilon, d.exact
            ),
        );
        let (n, what) = counted(&self.unreferenced_vertices, "vertices are used by no triangle");
        add("unreferenced-vertices", n, what);
        for a in &self.attribute_problems {
            add("attribute-length", 1, a.clone());
        }
        if let Some(uv) = &self.uv {
            if let Some(p) = &uv.index_problem {
                add("uv-indices", 1, p.clone());
            }
            add(
                "uv-non-finite",
                uv.non_finite_values,
                format!("{} UV values are NaN/Inf", uv.non_finite_values),
            );
            let (n, what) =
                counted(&uv.negative_area, "triangles are clockwise (mirrored) in UV space");
            add("uv-flipped", n, what);
            let (n, what) = counted(&uv.zero_area, "triangles have zero area in UV space");
            add("uv-zero-area", n, what);
        }
        w
    }

    /// `true` when [`problems`](Self::problems) is empty.
    pub fn is_clean(&self) -> bool {
        self.problems().is_empty()
    }

    /// A short human-readable description, one line per fact, for `fieldtex inspect`.
    pub fn summary_lines(&self) -> Vec<String> {
        let mut out =
            vec![format!("vertices: {}, triangles: {}", self.n_vertices, self.n_triangles)];
        match &self.bounding_box {
            Some(b) => out.push(format!(
                "bounding box: [{}, {}, {}] – [{}, {}, {}], diagonal {}",
                coordinate(b.min[0]),
                coordinate(b.min[1]),
                coordinate(b.min[2]),
                coordinate(b.max[0]),
                coordinate(b.max[1]),
                coordinate(b.max[2]),
                coordinate(self.diagonal)
            )),
            None => out.push("bounding box: none (no finite vertex)".into()),
        }
        out.push(format!(
            "components: {} ({} when cut at non-manifold edges/vertices), boundary loops: {}{}",
            self.components.count,
            self.components.edge_connected,
            self.boundary_loops.count,
            if self.boundary_loops.open_chains > 0 {
                format!(" ({} open chains)", self.boundary_loops.open_chains)
            } else {
                String::new()
            }
        ));
        for c in self.components.listed.iter().take(LISTED_ITEMS) {
            let topo = match (c.genus, c.nonorientable_genus) {
                (Some(g), _) => format!("genus {g}"),
                (None, Some(k)) => format!("non-orientable, {k} cross-caps"),
                _ => format!("genus n/a: {}", c.genus_unavailable.as_deref().unwrap_or("?")),
            };
            out.push(format!(
                "  component {}: {} triangles, {} vertices, χ = {}, {} boundary loops, {topo}",
                c.id, c.triangles, c.vertices, c.euler_characteristic, c.boundary_loops
            ));
        }
        let shown = self.components.listed.len().min(LISTED_ITEMS);
        if shown < self.components.count {
            out.push(format!(
                "  … and {} more components (smaller; `inspect --json` lists up to {})",
                self.components.count - shown,
                self.components.listed.len()
            ));
        }
        if let Some(a) = self.shape.min_angle_deg {
            out.push(format!("smallest angle: {a:.4}°"));
        }
        if let Some(uv) = &self.uv {
            let range = match (uv.min, uv.max) {
                (Some(a), Some(b)) => {
                    format!("[{:.4}, {:.4}] – [{:.4}, {:.4}]", a[0], a[1], b[0], b[1])
                }
                _ => "none".into(),
            };
            out.push(format!("UVs: {} values, range {range}", uv.values));
        } else {
            out.push("UVs: none".into());
        }
        let problems = self.problems();
        if problems.is_empty() {
            out.push("no problems found".into());
        }
        for p in problems {
            out.push(format!("problem {p}"));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::coordinate;

    #[test]
    fn coordinates_stay_short_at_any_magnitude() {
        assert_eq!(coordinate(0.0), "0.000000");
        assert_eq!(coordinate(-12.5), "-12.500000");
        assert_eq!(coordinate(1e38), "1.000000e38");
        assert_eq!(coordinate(-3e-30), "-3.000000e-30");
        for x in [1e300, 1.41e38, 2.5e-9, 123456.0, 0.001] {
            assert!(coordinate(x).len() <= 16, "{x}: {}", coordinate(x));
        }
    }
}
