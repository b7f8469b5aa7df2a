//! The experiments of Yamauchi & Beer, each coupling a [`ctrnn::Network`] with its environment and
//! scoring it: sequence learning (§5), one-dimensional navigation (§4) and landmark recognition
//! (§3).
#![warn(missing_docs)]
