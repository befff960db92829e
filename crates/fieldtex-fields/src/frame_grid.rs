//! The regular lattice of nodes that carries a 3-D frame field (paper E §3: a coarse
//! grid whose shortest side has 20–30 cells), with index ↔ position maps and the
//! nearest node of a point. Used by [`crate::frame_field_3d`].

use crate::FieldsError;

/// The regular grid of frame-field nodes: node `(i, j, k)` sits at
/// `origin + (i, j, k) · spacing`, `i < dims[0]`, …; node index `i + dims[0]·(j + dims[1]·k)`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FrameGrid {
    pub origin: [f64; 3],
    pub spacing: f64,
    pub dims: [usize; 3],
}

impl FrameGrid {
    /// A grid over the box `[min, max]` whose shortest side has `shortest_cells` cells
    /// (at least 2), with one node of margin on every side; the longest side is capped at
    /// `2 · shortest_cells` cells (the spacing grows for very elongated boxes).
    pub fn over_box(
        min: [f64; 3],
        max: [f64; 3],
        shortest_cells: usize,
    ) -> Result<Self, FieldsError> {
        Self::over_box_capped(min, max, shortest_cells, 2 * shortest_cells)
    }

    /// As [`FrameGrid::over_box`] with the longest side capped at `longest_cells` cells
    /// (the spacing grows for elongated boxes, so the shortest side gets fewer cells);
    /// this bounds the node count, and with it the factorisation and edit times.
    pub fn over_box_capped(
        min: [f64; 3],
        max: [f64; 3],
        shortest_cells: usize,
        longest_cells: usize,
    ) -> Result<Self, FieldsError> {
        let ext: Vec<f64> = (0..3).map(|a| max[a] - min[a]).collect();
        if ext.iter().any(|e| !e.is_finite() || *e < 0.0) {
            return Err(FieldsError::InvalidOption {
                name: "frame grid box",
                value: ext.iter().cloned().fold(f64::NAN, f64::min),
                expected: "a finite box with max ≥ min",
            });
        }
        if !(2..=256).contains(&shortest_cells) {
            return Err(FieldsError::InvalidOption {
                name: "frame grid shortest_cells",
                value: shortest_cells as f64,
                expected: "between 2 and 256",
            });
        }
        let longest = ext.iter().cloned().fold(0.0, f64::max).max(1e-12);
        let shortest = ext.iter().cloned().fold(f64::INFINITY, f64::min).max(longest * 1e-3);
        let spacing = (shortest / shortest_cells as f64).max(longest / longest_cells.max(2) as f64);
        let mut dims = [0usize; 3];
        let mut origin = [0.0; 3];
        for a in 0..3 {
            let cells = (ext[a] / spacing).ceil().max(1.0) as usize;
            dims[a] = cells + 3;
            let centre = 0.5 * (min[a] + max[a]);
            origin[a] = centre - 0.5 * (dims[a] - 1) as f64 * spacing;
        }
        Ok(Self { origin, spacing, dims })
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Whether the grid has no node (never for grids from [`FrameGrid::over_box`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of node `(i, j, k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Position of node `index`.
    pub fn position(&self, index: usize) -> [f64; 3] {
        let i = index % self.dims[0];
        let j = (index / self.dims[0]) % self.dims[1];
        let k = index / (self.dims[0] * self.dims[1]);
        [
            self.origin[0] + i as f64 * self.spacing,
            self.origin[1] + j as f64 * self.spacing,
            self.origin[2] + k as f64 * self.spacing,
        ]
    }

    /// The node nearest to `p` (clamped into the grid).
    pub fn nearest(&self, p: [f64; 3]) -> usize {
        let c: Vec<usize> = (0..3)
            .map(|a| {
                let t = ((p[a] - self.origin[a]) / self.spacing).round();
                t.clamp(0.0, (self.dims[a] - 1) as f64) as usize
            })
            .collect();
        self.index(c[0], c[1], c[2])
    }
}
