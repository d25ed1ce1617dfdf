//! The lane types of `pathlab-mc` ([`pathlab_mc::lanes`]), where code written once runs on one
//! value or on eight.

pub use pathlab_mc::lanes::*;
