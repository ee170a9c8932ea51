//! The pipeline file and the policies it names: [`config`] (`Pipeline`: which model, how to
//! train, which reduction, which parameters to run and validate) and [`fallback`] (what an
//! online run or a sweep does where the reduced answer is not trusted). The rooms above read
//! them: `training` (offline), `workflows` (online, sweeps, validation), `report`.

pub mod config;
pub mod fallback;

pub use config::Pipeline;
