//! The commands of the `flexrom` binary, one file each (its arguments and what it does), and
//! what they share: the `--csv`/`--json` and `--dense`/`--no-dense` flags and the printing of
//! tables and run details. `main.rs` parses the command line and dispatches here.

pub mod demo;
pub mod merge;
pub mod online;
pub mod run;
pub mod simulate;
pub mod sweep;
pub mod train;
pub mod validate;

use flexrom::output::table::{Format, Table};
use flexrom::output::{self, detail};
use flexrom::pipeline::dense::DenseChoice;

/// `--csv` / `--json`: how a command prints its results on stdout.
#[derive(clap::Args, Clone, Copy)]
pub struct FormatArgs {
    /// print the results as CSV on stdout (one header line)
    #[arg(long, conflicts_with = "json")]
    csv: bool,
    /// print the results as JSON on stdout
    #[arg(long)]
    json: bool,
}

impl FormatArgs {
    pub fn format(self) -> Format {
        Format::from_flags(self.csv, self.json)
    }
}

/// `--dense` / `--no-dense` of `validate` and `run` ([`flexrom::pipeline::dense`]).
#[derive(clap::Args, Clone, Copy)]
pub struct DenseArgs {
    /// skip the full run with a dense LU (its time and speedup are then empty)
    #[arg(long, conflicts_with = "dense")]
    no_dense: bool,
    /// run the dense-LU comparison even when its matrix is above 256 MiB (skipped by
    /// default there, with a line saying so)
    #[arg(long)]
    dense: bool,
}

impl DenseArgs {
    pub fn choice(self) -> DenseChoice {
        DenseChoice::from_flags(self.dense, self.no_dense)
    }
}

/// `--estimate METHOD` of `online`, `validate`, `sweep` and `run`: the error estimate's
/// method, over the pipeline's `[online] estimate` (docs/error-estimate.md).
#[derive(clap::Args, Clone, Copy)]
pub struct EstimateArgs {
    /// how the error estimate is computed, over the pipeline's [online] estimate (default:
    /// that, else "defects" where greedy training calibrated it, else "corrected")
    #[arg(long, value_enum, value_name = "METHOD")]
    estimate: Option<flexrom::pipeline::config::EstimateMethod>,
}

impl EstimateArgs {
    pub fn method(self) -> Option<flexrom::pipeline::config::EstimateMethod> {
        self.estimate
    }
}

pub fn check_scale(x: f64) -> flexrom::Result<()> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(flexrom::Error::Usage(format!("--load-scale must be finite, got {x}")))
    }
}

/// Prints the library's warnings on stderr, one `warning: ` line each (every verbosity).
pub fn warn(warnings: &[String]) {
    for w in warnings {
        flexrom::output::note(&format!("warning: {w}"));
    }
}

/// The warnings about finished runs of `rom` (extrapolation, estimates above the
/// tolerance), printed; with `strict`, an estimate above the tolerance is the error.
pub fn check_runs(rom: &flexrom::rom::Rom, runs: &[(f64, Option<f64>)], strict: bool) -> flexrom::Result<()> {
    let Some(trust) = rom.trust() else { return Ok(()) };
    warn(&flexrom::rom::trust::check_runs(trust, rom.estimator().is_some(), runs, strict)?);
    Ok(())
}

/// Prints `t` on stdout as CSV or JSON; nothing in text mode (the command's own lines, on
/// stderr or stdout, are its text form). `single`: the command's result is one record,
/// printed in JSON as one object rather than an array of one.
pub fn print_table(t: &Table, format: Format, single: bool) -> flexrom::Result<()> {
    match format {
        Format::Text => Ok(()),
        Format::Csv => output::print(&t.to_csv()?),
        Format::Json if single => output::println(&t.to_json_object()),
        Format::Json => output::println(&t.to_json()),
    }
}

/// `-v`: the settings and Newton statistics of one run.
pub fn run_details(r: &flexrom::simulate::SimulationResult) {
    let (s, st) = (&r.settings, &r.stats);
    detail(&format!(
        "  settings: dt {} s, t_end {} s, rho_inf {}, load scale {}, solver {:?}, {} coordinates",
        s.dt,
        s.t_end,
        s.rho_inf,
        s.mu.scale(),
        s.solver,
        r.q.nrows()
    ));
    detail(&format!(
        "  Newton: {:.2} iterations per step (at most {} in one step), {} factorizations, {} step cuts, {} steps at the round-off floor; {:.3} ms per step",
        st.newton_iterations as f64 / st.steps.max(1) as f64,
        st.max_iterations_in_a_step,
        st.factorizations,
        st.step_cuts,
        st.steps_at_round_off,
        1e3 * r.wall_seconds / st.steps.max(1) as f64
    ));
}
