//! Texture optimisation (Kwatra, Essa, Bobick & Kwatra 2005; Kwatra et al. 2007;
//! paper A §5) over surface-sample domains.
//!
//! Placeholder: the engine is being written (issue 4). This crate is split from
//! `fieldtex-synth` because its domain is an unstructured set of surface samples
//! with tangent frames and radius neighbour queries rather than a grid hierarchy.
