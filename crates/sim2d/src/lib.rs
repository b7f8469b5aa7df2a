//! A small 2-D robot world for the landmark-recognition experiment (paper §3): a room's walls and
//! boxes, a Nomad-200-like disc robot with differential drive, a sonar model and a hand-coded wall
//! follower. It knows no network.
//!
//! Not built yet: this crate is a placeholder so that the workspace has its final shape.
#![warn(missing_docs)]
