//! The cost model: `timing` (interleaved medians), `route` (which route, reduced or full, is
//! faster: train's `/timing`, the one-line notice, the report's verdict), `dense` (whether a
//! dense reference solve fits).

pub mod dense;
pub mod route;
pub mod timing;
