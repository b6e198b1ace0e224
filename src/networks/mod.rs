//! The learning part: Gaussian RBF bases S(Z), the weights ŴD, ŴC, ŴG with
//! their output and update, the learning policies and the weight pass's
//! instruction set. SPEC §6, §11, §13, §15.

pub mod learning;
pub mod network;
pub mod rbf;
pub mod simd;
