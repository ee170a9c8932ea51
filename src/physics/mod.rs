//! The mechanics: element, loads, time functions and the assembled system. Knows nothing of
//! reduction.
pub mod centre_line;
pub mod element;
pub mod joints;
pub mod loads;
pub mod masses;
pub mod parts;
pub mod section;
pub mod system;
pub mod time_function;
