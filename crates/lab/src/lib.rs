//! pathlab's experiments as functions that return data, for the command line, a notebook or a
//! viewer to present: a distribution's samples against its exact pdf ([`sample`]), Monte Carlo
//! integration of an expression with its error ([`integrate`], over the expression language of
//! [`expr`]), and the plots of both ([`plot`]).

pub mod expr;
pub mod integrate;
pub mod plot;
pub mod sample;
