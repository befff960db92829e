//! Edits of a [`FieldDesign`] (paper D's interactive design): placing, moving and
//! removing singularities, adding, replacing and removing strokes. Each edit marks what
//! the next solve must refresh (the singular terms, the stroke diagonal); the solve
//! itself is in `field_design.rs`.

use super::*;

impl FieldDesign {
    fn place(&self, s: Singularity) -> Result<SingularityEntry, FieldsError> {
        if s.kind.symmetry() != self.symmetry {
            return Err(FieldsError::WrongSymmetry {
                kind: s.kind.name(),
                symmetry: self.symmetry.name(),
            });
        }
        let fields = [
            ("x", s.position[0]),
            ("y", s.position[1]),
            ("z", s.position[2]),
            ("angle", s.angle),
            ("strength", s.strength),
        ];
        for (field, value) in fields {
            if !value.is_finite() {
                return Err(FieldsError::NonFinite { what: "singularity", index: 0, field, value });
            }
        }
        let outside = || FieldsError::OutsideDomain {
            what: "singularity",
            x: s.position[0],
            y: s.position[1],
            z: s.position[2],
        };
        let face = self.locate(s.position);
        if face.is_none()
            && (self.plane.is_none()
                || self.options.singularity_model == SingularityModel::PointDelta)
        {
            return Err(outside());
        }
        // Outside the plane is allowed, but not absurdly far (1000 domain sizes).
        if let (None, Some(g)) = (face, &self.plane) {
            let far = 1e3 * (g.width + g.height);
            if s.position[0].abs() > far || s.position[1].abs() > far || s.position[2].abs() > far {
                return Err(outside());
            }
        }
        // Keep the model field's pole off vertices and edges (its edge integrals would be
        // undefined there): nudge the barycentric coordinates towards the centre.
        let (face, origin) = match face {
            Some((f, b)) => {
                let min = b[0].min(b[1]).min(b[2]);
                let b = if min < 1e-6 {
                    std::array::from_fn(|k| (1.0 - 1e-4) * b[k] + 1e-4 / 3.0)
                } else {
                    b
                };
                let t = self.dec.triangles[f];
                let mut o = [0.0; 3];
                for k in 0..3 {
                    o = add(o, scale(self.dec.positions[t[k] as usize], b[k]));
                }
                if self.plane.is_some() {
                    o[2] = 0.0;
                }
                (Some((f, b)), o)
            }
            None => (None, s.position),
        };
        Ok(SingularityEntry { singularity: s, face, origin, one_form: None })
    }

    /// Adds a singularity (right-hand side only). Errors: wrong kind for the design's
    /// symmetry, non-finite values, outside a mesh domain (on the plane a singularity may
    /// lie outside the rectangle; it then shapes the field from there).
    pub fn add_singularity(&mut self, s: Singularity) -> Result<SingularityId, FieldsError> {
        let entry = self.place(s)?;
        self.singularities.push(Some(entry));
        Ok(SingularityId(self.singularities.len() as u32 - 1))
    }

    fn entry_mut(
        &mut self,
        id: SingularityId,
    ) -> Result<&mut Option<SingularityEntry>, FieldsError> {
        match self.singularities.get_mut(id.0 as usize) {
            Some(e @ Some(_)) => Ok(e),
            _ => Err(FieldsError::UnknownId { what: "singularity", id: id.0 }),
        }
    }

    /// Replaces a singularity (kind, position, angle, strength); right-hand side only.
    pub fn set_singularity(
        &mut self,
        id: SingularityId,
        s: Singularity,
    ) -> Result<(), FieldsError> {
        self.entry_mut(id)?;
        let entry = self.place(s)?;
        *self.entry_mut(id)? = Some(entry);
        Ok(())
    }

    /// Moves a singularity; right-hand side only.
    pub fn move_singularity(
        &mut self,
        id: SingularityId,
        position: [f64; 3],
    ) -> Result<(), FieldsError> {
        let mut s = self.entry_mut(id)?.as_ref().expect("checked").singularity;
        s.position = position;
        self.set_singularity(id, s)
    }

    /// Removes a singularity; right-hand side only. Its id is not reused.
    pub fn remove_singularity(&mut self, id: SingularityId) -> Result<(), FieldsError> {
        *self.entry_mut(id)? = None;
        Ok(())
    }

    /// Adds a direction stroke (changes the matrix diagonal; refactored on the next solve).
    pub fn add_stroke(&mut self, stroke: Stroke) -> Result<StrokeId, FieldsError> {
        let index = self.strokes.len();
        let constraints = self.stroke_constraints(&stroke, index)?;
        self.strokes.push(Some((stroke, constraints)));
        self.stroke_diag = None;
        Ok(StrokeId(index as u32))
    }

    /// Removes a stroke. Its id is not reused.
    pub fn remove_stroke(&mut self, id: StrokeId) -> Result<(), FieldsError> {
        match self.strokes.get_mut(id.0 as usize) {
            Some(s @ Some(_)) => {
                *s = None;
                self.stroke_diag = None;
                Ok(())
            }
            _ => Err(FieldsError::UnknownId { what: "stroke", id: id.0 }),
        }
    }

    /// Replaces a stroke's polyline (and weight).
    pub fn set_stroke(&mut self, id: StrokeId, stroke: Stroke) -> Result<(), FieldsError> {
        if !matches!(self.strokes.get(id.0 as usize), Some(Some(_))) {
            return Err(FieldsError::UnknownId { what: "stroke", id: id.0 });
        }
        let constraints = self.stroke_constraints(&stroke, id.0 as usize)?;
        self.strokes[id.0 as usize] = Some((stroke, constraints));
        self.stroke_diag = None;
        Ok(())
    }

    /// The edge constraints of `stroke` as stroke number `index` (paper D's stroke term).
    fn stroke_constraints(
        &self,
        stroke: &Stroke,
        index: usize,
    ) -> Result<Vec<EdgeConstraint>, FieldsError> {
        let locate = |p: [f64; 3]| self.locate(p);
        stroke_edge_constraints(
            &self.dec,
            &locate,
            &self.frames,
            self.symmetry,
            stroke,
            self.options.stroke_weight,
            index,
        )
    }
}
