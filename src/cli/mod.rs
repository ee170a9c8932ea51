//! The commands of the `flexrom` binary, one file each (its arguments and what it does), and
//! what they share: the `--csv`/`--json` and `--dense`/`--no-dense` flags and the printing of
//! tables and run details. `main.rs` parses the command line and dispatches here.

pub mod animate;
pub mod demo;
pub mod merge;
pub mod modes;
pub mod online;
pub mod run;
pub mod simulate;
pub mod statics;
pub mod sweep;
pub mod train;
pub mod validate;
pub mod values;

use flexrom::cost::dense::DenseChoice;
use flexrom::output::table::{Format, Table};
use flexrom::output::{self, detail};
use flexrom::solver::parameters::Parameters;

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

/// `--dense` / `--no-dense` of `validate` and `run` ([`flexrom::cost::dense`]).
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
    estimate: Option<values::Method>,
}

impl EstimateArgs {
    pub fn method(self) -> Option<flexrom::pipeline::config::EstimateMethod> {
        self.estimate.map(Into::into)
    }
}

/// `--param NAME=VALUE` (repeatable): the model's named parameters (`scaled = "drive"` on a
/// load; a body's modulus or density, a spring's stiffness, a point mass), beside
/// `--load-scale`.
#[derive(clap::Args, Clone, Default)]
pub struct ParamArgs {
    /// a named parameter of the model: a load's factor (`scaled = "NAME"`), e.g. `--param
    /// drive=1.1`, or a value the model file names (`{ value, parameter = "NAME" }`): a body's
    /// Young's modulus in Pa or density in kg/m³, a spring's stiffness in N/m (N·m/rad), a
    /// point mass in kg, e.g. `--param E_lower=2.5e8`, `--param payload=2`; repeat it for several;
    /// `--param load_scale=X` is `--load-scale X`; parameters not given keep the model file's
    /// loads and values
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param, allow_negative_numbers = true)]
    params: Vec<(String, f64)>,
}

fn parse_param(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s.split_once('=').ok_or_else(|| format!("`{s}` is not NAME=VALUE"))?;
    if !flexrom::solver::parameters::is_parameter_name(name.trim()) {
        return Err(format!("`{s}` is not NAME=VALUE (a name is letters, digits and `_`, starting with a letter)"));
    }
    let v: f64 = value.trim().parse().map_err(|_| format!("`{value}` (parameter {name}) is not a number"))?;
    Ok((name.trim().to_string(), v))
}

impl ParamArgs {
    /// Whether `--param load_scale=X` was given.
    pub fn sets_load_scale(&self) -> bool {
        self.params.iter().any(|(n, _)| n == flexrom::solver::parameters::LOAD_SCALE)
    }

    /// Whether any `--param` was given.
    pub fn any(&self) -> bool {
        !self.params.is_empty()
    }

    /// The parameters of `--load-scale` (if given, else `default_scale`) and every
    /// `--param`; a parameter given twice, or `--param load_scale` beside `--load-scale`,
    /// is refused.
    pub fn parameters(&self, load_scale: Option<f64>, default_scale: f64) -> flexrom::Result<Parameters> {
        use flexrom::solver::parameters::LOAD_SCALE;
        let mut mu = Parameters::load_scale(load_scale.unwrap_or(default_scale));
        let mut seen: Vec<&str> = load_scale.map(|_| LOAD_SCALE).into_iter().collect();
        for (name, value) in &self.params {
            if seen.contains(&name.as_str()) {
                let twice = if name == LOAD_SCALE {
                    "--load-scale and --param load_scale".to_string()
                } else {
                    format!("--param {name}")
                };
                return Err(flexrom::Error::usage(format!("{twice} given twice")));
            }
            seen.push(name);
            mu = mu.with(name, *value);
        }
        mu.validate()?;
        Ok(mu)
    }
}

/// How the command line writes an option the library names by its key
/// ([`flexrom::Error::render`]): `load_scale` is `--load-scale`, its value after a space.
pub fn flag(key: &str, value: Option<&str>) -> String {
    let name = format!("--{}", key.replace('_', "-"));
    value.map_or_else(|| name.clone(), |v| format!("{name} {v}"))
}

/// An error's one line as the command line shows it: its options as flags.
pub fn message(e: &flexrom::Error) -> String {
    e.render(&flag)
}

/// Prints the library's warnings on stderr, one `warning: ` line each (every verbosity),
/// their options as flags.
pub fn warn<W: flexrom::error::Said>(warnings: &[W]) {
    for w in warnings {
        flexrom::output::note(&format!("warning: {}", w.said(&flag)));
    }
}

/// The warnings of a model file's own `[time] dt` that does not resolve the model
/// ([`flexrom::simulate::resolution_warnings`]): what `train` and `run` say before training.
pub fn model_resolution(model: &flexrom::model::Model) -> Vec<String> {
    let overrides = flexrom::simulate::Overrides::default();
    flexrom::simulate::Settings::resolve(model, &overrides)
        .map_or_else(|_| Vec::new(), |s| flexrom::simulate::resolution_warnings(model, &s))
}

/// Says the warnings after reduced answers ([`flexrom::rom::Rom::warnings_after`]); with
/// `strict`, an estimate above the tolerance is the error (exit code 4) and a basis without a
/// tolerance is warned of.
pub fn warn_after(
    warnings: flexrom::Result<Vec<String>>,
    rom: &flexrom::rom::Rom,
    strict: bool,
) -> flexrom::Result<()> {
    warn(&warnings?);
    if strict && rom.trust().is_some_and(|t| t.held_tolerance().is_none()) {
        warn(&[format!(
            "{}: no tolerance to hold the estimates to (set [online] tolerance in the pipeline)",
            flag("strict", None)
        )]);
    }
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

/// Prints a run's time series on stdout ([`flexrom::report::tables::series_table`], one
/// row per instant) as CSV or JSON; nothing in text mode. `simulate --csv/--json` and
/// `online --csv` print it alike.
pub fn print_series(
    model: &flexrom::model::Model,
    r: &flexrom::simulate::SimulationResult,
    format: Format,
) -> flexrom::Result<()> {
    if format == Format::Text {
        return Ok(());
    }
    print_table(&flexrom::report::tables::series_table(model, r), format, false)
}

/// `-v`: the settings and Newton statistics of one run (`reduced`: of a reduced model, whose
/// strain check sees its sampled elements only).
pub fn run_details(r: &flexrom::simulate::SimulationResult, reduced: bool) {
    let (s, st) = (&r.settings, &r.stats);
    detail(&format!(
        "  settings: dt {} s, t_end {} s, rho_inf {}, {}, solver {:?}, Newton start {}, {} coordinates",
        s.dt,
        s.t_end,
        s.rho_inf,
        s.mu,
        s.solver,
        s.params.predictor.name(),
        r.q.nrows()
    ));
    detail(&format!(
        "  Newton: {:.2} iterations per step (halved steps' attempts included; at most {} in one attempt), {} factorizations, {} step cuts, {} steps at the round-off floor; {:.3} ms per step",
        st.newton_iterations as f64 / st.steps.max(1) as f64,
        st.max_iterations_in_a_step,
        st.factorizations,
        st.step_cuts,
        st.steps_at_round_off,
        1e3 * r.wall_seconds / st.steps.max(1) as f64
    ));
    if let Some(l) = st.largest_strain {
        // how hard the run pulled the beams: flexrom fails a run only above the blow-up bound
        // (`[time] max_strain`), far above what most structural materials stay elastic at
        detail(&format!(
            "  largest mean axial strain |ε̄| = {:.2e} (element {}{}, t = {:.4} s; checked every {} steps), blow-up bound {}",
            l.strain,
            l.element,
            if reduced { ", of the sampled ones" } else { "" },
            l.t,
            flexrom::simulate::STRAIN_CHECK_EVERY,
            s.params.max_strain
        ));
    }
    if s.params.predictor == flexrom::solver::generalized_alpha::Predictor::Adaptive {
        // which guess the adaptive start took (docs/reduced-speed.md): a model that always
        // takes one may as well name it in `[time] predictor`
        // a halved step's parts count each, so the three may sum past the steps
        detail(&format!(
            "  Newton's start: {} of the steps solved ({} steps, a halved step's parts counted each)",
            st.starts(),
            st.steps
        ));
    }
}
