//! Solid texture synthesis from 2-D exemplars guided by a 3-D frame field (paper E,
//! Zhang, Du, Lai, Ni & Hu 2010, "Sketch guided solid texturing"; built on Dong,
//! Lefebvre, Tong & Drettakis 2008, "Lazy solid texture synthesis", and Lefebvre &
//! Hoppe 2005).
//!
//! - [`solid_exemplar`]: per plane and level the Gaussian stack, the PCA of `N × N`
//!   neighbourhoods and the projected appearance of every pixel; [`candidate_triples`]:
//!   crossbar-consistent coordinate triples (`N_T` per pixel).
//! - [`voxel_lattice`]: the infinite per-level voxel lattice, its world placement, the
//!   primary and dual block partitions, and [`FrameSource`] (the field the synthesis
//!   follows, given as rotation matrices so this crate needs no field type).
//! - [`lazy_solid_synthesis`]: [`SolidSynthesizer`], the engine: slab initialisation,
//!   field-aware upsampling, field-aligned correction with dual-grid history windows,
//!   evaluation of a requested voxel subset from its dependency set, cached by block.
//!
//! ```no_run
//! use fieldtex_synth::solid::*;
//! # fn demo(img: &fieldtex_core::Image) -> Result<(), fieldtex_synth::SynthError> {
//! let progress = fieldtex_core::NoProgress;
//! let ex = SolidExemplar::new([img, img, img], &SolidAnalysisOptions::default(), &progress)?;
//! let field = ConstantFrame([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
//! let lattice = VoxelLattice { origin: [0.0; 3], spacing: 0.01 };
//! let mut synth = SolidSynthesizer::new(&ex, lattice, &field, SolidSynthesisOptions::default())?;
//! let (rgb, stats) = synth.colors(&[[0, 0, 0], [5, 7, 9]], &progress);
//! # let _ = (rgb, stats); Ok(()) }
//! ```

// Loops over the three planes and the PCA dimensions read like the maths.
#![allow(clippy::needless_range_loop)]

pub mod candidate_triples;
mod integrated_init;
pub mod lazy_solid_synthesis;
pub mod solid_exemplar;
pub mod voxel_lattice;

#[cfg(test)]
mod tests;

pub use candidate_triples::{CandidateTriples, Triple};
pub use lazy_solid_synthesis::{LevelStats, SolidCache, SolidSynthesisOptions, SolidSynthesizer};
pub use solid_exemplar::{SolidAnalysisOptions, SolidExemplar};
pub use voxel_lattice::{ConstantFrame, FrameSource, VoxelLattice};
