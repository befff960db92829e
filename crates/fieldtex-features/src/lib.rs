//! Salient curves on meshes (being written).
