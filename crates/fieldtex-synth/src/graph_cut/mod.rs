//! Graph cuts for texture synthesis: the Boykov–Kolmogorov max-flow ([`max_flow`]).
pub mod max_flow;
pub use max_flow::MaxFlow;
