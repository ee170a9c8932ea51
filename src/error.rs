//! One error type for the whole program. Every variant carries the context a user needs to
//! act on it: the file and field for bad input, the time, iteration and residual for a
//! failed solve.

use std::fmt;
use std::path::Path;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad input: names the file, the field (a dotted path such as `bodies[1].length`) and
    /// the problem.
    #[error("{file}: {field}: {problem}")]
    Input { file: String, field: String, problem: Text },

    /// Reading or writing a file failed at the operating-system level.
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },

    /// An HDF5 file is missing, truncated, foreign or inconsistent.
    #[error("{file}: {problem}")]
    Hdf5 { file: String, problem: String },

    /// Newton did not converge even after the allowed number of step halvings.
    #[error(
        "Newton failed at t = {t:.6} s (step {dt:.3e} s after {cuts} halvings): \
         {iterations} iterations, last increment {increment:.3e}, residual {residual:.3e}"
    )]
    NewtonFailed { t: f64, dt: f64, cuts: u32, iterations: usize, increment: f64, residual: f64 },

    /// The iteration matrix could not be factored (singular system).
    #[error("linear solve failed at t = {t:.6} s: {problem}")]
    LinearSolve { t: f64, problem: String },

    /// A numerical step failed where no time is known: a linear system's factorization or
    /// solve, a POD, an NNLS fit. `what` names the step (`linear solve`, `POD`, `NNLS`); a
    /// caller that knows the time makes a linear solve's failure an [`Error::LinearSolve`]
    /// ([`Error::at_time`]).
    #[error("{what}: {problem}")]
    Numerical { what: &'static str, problem: String },

    /// What a failed numerical step was for (`enriched basis`, `block 2`), before the
    /// step's own failure ([`Error::context`]).
    #[error("{context}: {source}")]
    Context {
        context: String,
        #[source]
        source: Box<Error>,
    },

    /// Strict checking (`--strict`): a run's error estimate exceeds the tolerance (its output
    /// is written; the program exits with code 4). `warnings`: what the front end says
    /// before the error (extrapolation, amplification), as it would without strict.
    #[error("{}: {message}", plain_option("strict", None))]
    Strict { message: String, warnings: Vec<String> },

    /// Anything else that is a usage error of the program (bad command-line values).
    #[error("{0}")]
    Usage(Text),

    /// A bad value of a run's option, named by its key (`load_scale`, `shard`, `dt`,
    /// `max_memory`) and not as a front end spells it: the command line renders it as
    /// `--load-scale`, Python as the keyword `load_scale=` ([`Error::render`]). `value`: the
    /// value given, where the message shows it.
    #[error("{}", option_message(key, value.as_deref(), &problem.to_string(), &plain_option))]
    Option { key: &'static str, value: Option<String>, problem: Text },

    /// A run or an allocation would exceed a resource bound (memory, step count): names
    /// the estimated figure, the bound and the option or key that raises it.
    #[error("{0}")]
    Resource(Text),

    /// A run left plausible bounds (strain, step cuts): names what, when, and the key or
    /// option that relaxes the check.
    #[error("blow-up at t = {t:.6} s: {problem}")]
    BlowUp { t: f64, problem: Text },

    /// A numerical failure with the stage (simulate, train, online, validate, sweep) and
    /// the parameters it happened at (as `Parameters` print them: `load scale 1.1`); the
    /// time is in `source`.
    #[error("{stage} at {parameters}: {source}")]
    Stage {
        stage: String,
        parameters: String,
        #[source]
        source: Box<Error>,
    },

    /// A failure with what the user can do about it, after the failure's own text.
    #[error("{source}; {hint}")]
    Hinted {
        #[source]
        source: Box<Error>,
        hint: Text,
    },

    /// The host program asked the computation to stop ([`crate::interrupt`]: Ctrl-C in
    /// Python); temporary files begun are removed as the error travels up.
    #[error("interrupted")]
    Interrupted,

    /// Standard output was closed by the reader (`| head`): not an error of the run, the
    /// program ends quietly.
    #[error("standard output closed")]
    StdoutClosed,

    /// Some of many independent runs failed (a sweep's load scales); the others were
    /// written. Exit code 3.
    #[error("{0}")]
    PartlyFailed(String),
}

pub type Result<T> = std::result::Result<T, Error>;

/// The exit code of `--strict` when an error estimate exceeds the tolerance.
pub const STRICT_EXIT_CODE: u8 = 4;

/// A number as written by hand: plain in [1e-4, 1e6), else in exponent form (1e300 is
/// not 301 digits). Every message that prints a user's number (a load scale, a bound)
/// uses it, so it lives with the error type at the bottom of the layers.
pub fn show_number(x: f64) -> String {
    if x == 0.0 || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A text from a file or the environment as a message shows it: control characters (a
/// newline, a NUL, an escape sequence) escaped as `\n`, `\0`, `\u{1b}`, so an error stays
/// one line and a file cannot write to the terminal through it; everything else as it is.
pub fn show_text(s: &str) -> String {
    s.chars().map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() }).collect()
}

/// How a front end writes an option the library names by its key: the command line as its
/// flag (`--load-scale 2`), Python as its keyword (`load_scale=2`), the library's own text as
/// the key (`load_scale = 2`). `value` is `None` where the message does not show it.
pub trait Spelling {
    /// The option `key` (with `value`) as this front end's users write it, or `None` where
    /// they have no such option: a [`Text`] then leaves out the clause that names it.
    fn option(&self, key: &str, value: Option<&str>) -> Option<String>;
}

/// A front end that has every option: a function from the key and the value to its spelling.
impl<F: Fn(&str, Option<&str>) -> String> Spelling for F {
    fn option(&self, key: &str, value: Option<&str>) -> Option<String> {
        Some(self(key, value))
    }
}

/// How a front end writes an option ([`Spelling`]; the name [`Error::render`] takes).
pub type OptionSpelling = dyn Spelling;

/// A message's text that names options by their keys, for each front end to spell
/// ([`Spelling`]): words, and options each in the clause that goes with it (`; ` `--allow-blowup`
/// ` only warns`), which a front end without the option leaves out whole. Displayed, it is
/// the library's own text, the options as their keys (`allow_blowup only warns`); a front
/// end renders it with [`Text::render`] (through [`Error::render`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Text(Vec<Piece>);

#[derive(Clone, Debug, PartialEq)]
enum Piece {
    Words(String),
    /// `before`, the option as spelt, `after`; nothing where the front end lacks the option.
    Clause {
        before: String,
        key: &'static str,
        value: Option<String>,
        after: String,
    },
}

impl Text {
    /// `words`, then what is added after them.
    pub fn new(words: impl Into<String>) -> Text {
        Text(vec![Piece::Words(words.into())])
    }

    /// `words` added at the end.
    pub fn then(mut self, words: impl Into<String>) -> Text {
        self.0.push(Piece::Words(words.into()));
        self
    }

    /// `other` added at the end.
    pub fn append(mut self, other: Text) -> Text {
        self.0.extend(other.0);
        self
    }

    /// The option `key` (with `value`) added at the end, as each front end spells it.
    pub fn option(self, key: &'static str, value: Option<&str>) -> Text {
        self.clause("", key, value, "")
    }

    /// The clause `before OPTION after` added at the end; a front end without the option
    /// leaves the clause out (`; --allow-blowup only warns` is nothing in Python).
    pub fn clause(
        mut self,
        before: impl Into<String>,
        key: &'static str,
        value: Option<&str>,
        after: impl Into<String>,
    ) -> Text {
        let value = value.map(str::to_string);
        self.0.push(Piece::Clause { before: before.into(), key, value, after: after.into() });
        self
    }

    /// The text with each option as `spell` writes it.
    pub fn render(&self, spell: &OptionSpelling) -> String {
        let mut out = String::new();
        for piece in &self.0 {
            match piece {
                Piece::Words(w) => out.push_str(w),
                Piece::Clause { before, key, value, after } => {
                    if let Some(o) = spell.option(key, value.as_deref()) {
                        out.push_str(&format!("{before}{o}{after}"));
                    }
                }
            }
        }
        out
    }

    /// `c: ` put before the text ([`Error::context`]).
    fn prefixed(mut self, c: impl fmt::Display) -> Text {
        self.0.insert(0, Piece::Words(format!("{c}: ")));
        self
    }
}

impl fmt::Display for Text {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.render(&plain_option))
    }
}

/// A line the library hands a front end to say — a warning, a note: plain words, or a
/// [`Text`] that names options, as the front end's `spell` writes them.
pub trait Said {
    fn said(&self, spell: &OptionSpelling) -> String;
}

impl Said for String {
    fn said(&self, _spell: &OptionSpelling) -> String {
        self.clone()
    }
}

impl Said for Text {
    fn said(&self, spell: &OptionSpelling) -> String {
        self.render(spell)
    }
}

impl From<String> for Text {
    fn from(words: String) -> Text {
        Text::new(words)
    }
}

impl From<&str> for Text {
    fn from(words: &str) -> Text {
        Text::new(words)
    }
}

/// An option's message with the option as `spell` writes it: `OPTION VALUE: problem`, or
/// `OPTION problem` without a value (`--load-scale must be finite, got NaN`); the key where
/// the front end has no such option.
fn option_message(key: &str, value: Option<&str>, problem: &str, spell: &OptionSpelling) -> String {
    let option = spell.option(key, value).unwrap_or_else(|| plain_option(key, value));
    match value {
        Some(_) => format!("{option}: {problem}"),
        None => format!("{option} {problem}"),
    }
}

/// The library's own spelling of an option: its key, and ` = value` (`load_scale = NaN`).
fn plain_option(key: &str, value: Option<&str>) -> String {
    value.map_or(key.to_string(), |v| format!("{key} = {v}"))
}

/// The step [`Error::Numerical`] names for a linear system's factorization or solve.
pub const LINEAR_SOLVE: &str = "linear solve";

/// What to do after a reduced run failed ([`Error::at_reduced_stage`]; a sweep says it once
/// after its failures).
pub const REDUCED_RUN_FAILED: &str =
    "a reduced model can fail where the full one does not (its basis lacks this load's \
     motion): `flexrom simulate` runs the full model at this load, `flexrom sweep --full` at many, and a training run \
     near it puts its motion into the basis";
/// The same where the full model has just run at those parameters (`validate`).
pub const REDUCED_RUN_FAILED_FULL_RAN: &str =
    "the full model ran here, so the basis lacks this load's motion: a training run near it puts it in";

impl Error {
    /// The process exit code for this error: 3 when only part of the work failed
    /// ([`Error::PartlyFailed`]), 4 when an error estimate exceeded the tolerance under
    /// `--strict` ([`Error::Strict`]), 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::PartlyFailed(_) => 3,
            Error::Strict { .. } => STRICT_EXIT_CODE,
            _ => 1,
        }
    }

    pub fn input(file: impl AsRef<Path>, field: impl Into<String>, problem: impl Into<Text>) -> Self {
        Error::Input { file: file.as_ref().display().to_string(), field: field.into(), problem: problem.into() }
    }

    pub fn io(file: impl AsRef<Path>, source: std::io::Error) -> Self {
        Error::Io { file: file.as_ref().display().to_string(), source }
    }

    /// Whether this is a run's numerical failure (Newton, a linear solve, a blow-up), also
    /// with its stage or hint added: what a model can do at some parameters and not at
    /// others, as opposed to a stop asked for, a limit, or a file's problem.
    pub fn is_numerical(&self) -> bool {
        match self {
            Error::NewtonFailed { .. } | Error::LinearSolve { .. } | Error::BlowUp { .. } => true,
            Error::Stage { source, .. } | Error::Hinted { source, .. } | Error::Context { source, .. } => {
                source.is_numerical()
            }
            _ => false,
        }
    }

    /// Adds the stage and the parameters to a numerical failure (Newton, linear solve,
    /// blow-up); other errors already name their file or option and pass unchanged.
    pub fn at_stage(self, stage: &str, mu: &impl std::fmt::Display) -> Self {
        match self {
            Error::NewtonFailed { .. } | Error::LinearSolve { .. } | Error::BlowUp { .. } => {
                Error::Stage { stage: stage.to_string(), parameters: mu.to_string(), source: Box::new(self) }
            }
            other => other,
        }
    }

    /// [`Self::at_stage`] for a reduced run, with the way on after its failure: a reduced
    /// model can fail (blow up, or Newton not converge) where the full one does not — its
    /// basis lacks this load's motion —, and the full model is the exact route. `full_ran`:
    /// the full model has just run at these parameters (`validate`), so that is known.
    pub fn at_reduced_stage(self, stage: &str, mu: &impl std::fmt::Display, full_ran: bool) -> Self {
        match self {
            Error::NewtonFailed { .. } | Error::LinearSolve { .. } | Error::BlowUp { .. } => {
                let hint = if full_ran { REDUCED_RUN_FAILED_FULL_RAN } else { REDUCED_RUN_FAILED };
                Error::Hinted { source: Box::new(self.at_stage(stage, mu)), hint: hint.into() }
            }
            other => other,
        }
    }

    /// A usage error ([`Error::Usage`]) with the text `t`, whose options each front end
    /// spells ([`Text`]).
    pub fn usage(t: impl Into<Text>) -> Self {
        Error::Usage(t.into())
    }

    /// A bad value of the option `key` ([`Error::Option`]).
    pub fn option(key: &'static str, value: Option<String>, problem: impl Into<Text>) -> Self {
        Error::Option { key, value, problem: problem.into() }
    }

    /// The message with each option written as a front end's users write it (`spell`:
    /// `--load-scale 2` on the command line, `load_scale=2` in Python), also under a stage,
    /// a hint or a context; every other text as [`std::fmt::Display`] gives it.
    pub fn render(&self, spell: &OptionSpelling) -> String {
        match self {
            Error::Input { file, field, problem } => format!("{file}: {field}: {}", problem.render(spell)),
            Error::Option { key, value, problem } => {
                option_message(key, value.as_deref(), &problem.render(spell), spell)
            }
            Error::Strict { message, .. } => {
                let option = spell.option("strict", None).unwrap_or_else(|| plain_option("strict", None));
                format!("{option}: {message}")
            }
            Error::Resource(text) | Error::Usage(text) => text.render(spell),
            Error::BlowUp { t, problem } => format!("blow-up at t = {t:.6} s: {}", problem.render(spell)),
            Error::Stage { stage, parameters, source } => format!("{stage} at {parameters}: {}", source.render(spell)),
            Error::Hinted { source, hint } => format!("{}; {}", source.render(spell), hint.render(spell)),
            Error::Context { context, source } => format!("{context}: {}", source.render(spell)),
            other => other.to_string(),
        }
    }

    /// A linear system's factorization or solve failed ([`Error::Numerical`] with
    /// [`LINEAR_SOLVE`]).
    pub fn linear_solve(problem: impl Into<String>) -> Self {
        Error::Numerical { what: LINEAR_SOLVE, problem: problem.into() }
    }

    /// A numerical step's failure ([`Error::Numerical`]).
    pub fn numerical(what: &'static str, problem: impl Into<String>) -> Self {
        Error::Numerical { what, problem: problem.into() }
    }

    /// A failed linear solve placed at time `t` ([`Error::LinearSolve`]; another numerical
    /// step keeps its name in the problem); every other error passes unchanged.
    pub fn at_time(self, t: f64) -> Self {
        match self {
            Error::Numerical { what: LINEAR_SOLVE, problem } => Error::LinearSolve { t, problem },
            Error::Numerical { what, problem } => Error::LinearSolve { t, problem: format!("{what}: {problem}") },
            Error::Context { context, source } => source.at_time_in(t, &context),
            other => other,
        }
    }

    /// [`Self::at_time`] with what the solve was for put before its problem (`initial joint
    /// projection: …`).
    pub fn at_time_in(self, t: f64, context: &str) -> Self {
        match self.at_time(t) {
            Error::LinearSolve { t, problem } => Error::LinearSolve { t, problem: format!("{context}: {problem}") },
            other => other,
        }
    }

    /// What the failing step was for (`enriched basis`, `block 2`) put before the problem of
    /// a bad value, a bound, a linear solve or an HDF5 finding (the variant stays, so does
    /// what it tells the caller), or before a numerical step's failure
    /// ([`Error::Context`]). Other errors name their file and field already and pass
    /// unchanged.
    pub fn context(self, c: impl std::fmt::Display) -> Self {
        match self {
            Error::Usage(p) => Error::Usage(p.prefixed(c)),
            Error::Resource(p) => Error::Resource(p.prefixed(c)),
            e @ (Error::Numerical { .. } | Error::Context { .. }) => {
                Error::Context { context: c.to_string(), source: Box::new(e) }
            }
            Error::LinearSolve { t, problem } => Error::LinearSolve { t, problem: format!("{c}: {problem}") },
            Error::Hdf5 { file, problem } => Error::Hdf5 { file, problem: format!("{c}: {problem}") },
            other => other,
        }
    }

    /// The problem a lower layer found, without the file or the step it names: what a caller
    /// that knows the file and the field puts after them ([`Error::input`]). A bad value
    /// ([`Error::Usage`]), a bound ([`Error::Resource`]) and what an HDF5 check found
    /// ([`Error::Hdf5`]) give their text; another error gives its whole message.
    pub fn problem(self) -> String {
        match self {
            Error::Hdf5 { problem: p, .. } => p,
            Error::Usage(p) => p.to_string(),
            Error::Resource(p) => p.to_string(),
            Error::Numerical { what: LINEAR_SOLVE, problem } => problem,
            other => other.to_string(),
        }
    }

    /// [`Self::problem`] with the options a bound's text names kept for each front end to
    /// spell ([`Text`]): what a caller puts after the file and the field where the problem
    /// may be a bound ([`Error::Resource`]).
    pub fn problem_text(self) -> Text {
        match self {
            Error::Resource(text) | Error::Usage(text) => text,
            other => other.problem().into(),
        }
    }

    pub fn hdf5(file: impl AsRef<Path>, problem: impl std::fmt::Display) -> Self {
        Error::Hdf5 { file: file.as_ref().display().to_string(), problem: problem.to_string() }
    }
}

/// The command line's spelling of an option (src/cli/mod.rs `flag`: `--load-scale 2`), for
/// the library's tests of the texts it shows.
#[cfg(test)]
pub(crate) fn cli_flag(key: &str, value: Option<&str>) -> String {
    let name = format!("--{}", key.replace('_', "-"));
    value.map_or_else(|| name.clone(), |v| format!("{name} {v}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A factorization's failure reads as before once the integrator places it at its time;
    /// the context a caller adds keeps the variant and comes first.
    #[test]
    fn a_numerical_failure_gets_its_time_and_its_context() {
        let e = Error::linear_solve("the iteration matrix is singular (zero pivot 3 of 8)");
        assert_eq!(e.to_string(), "linear solve: the iteration matrix is singular (zero pivot 3 of 8)");
        let at = Error::linear_solve("singular").at_time_in(0.5, "modes");
        assert_eq!(at.to_string(), "linear solve failed at t = 0.500000 s: modes: singular");
        assert!(at.is_numerical());
        let pod = Error::numerical("POD", "empty").context("block 2");
        assert_eq!(pod.to_string(), "block 2: POD: empty");
        assert_eq!(pod.at_time(1.0).to_string(), "linear solve failed at t = 1.000000 s: block 2: POD: empty");
        let usage = Error::usage("count must be at least 1").context("reduction.multiplier_modes");
        assert!(
            matches!(&usage, Error::Usage(p) if p.to_string() == "reduction.multiplier_modes: count must be at least 1")
        );
        assert_eq!(usage.problem(), "reduction.multiplier_modes: count must be at least 1");
    }

    /// An option is named by its key, and each front end spells it its own way, also under
    /// a stage.
    #[test]
    fn an_option_is_spelt_by_the_front_end() {
        let e = Error::option("time", Some("1.5".into()), "outside the model's run");
        assert_eq!(e.to_string(), "time = 1.5: outside the model's run");
        assert_eq!(e.render(&cli_flag), "--time 1.5: outside the model's run");
        let e = Error::option("load_scale", None, "must be finite, got NaN");
        assert_eq!(e.render(&cli_flag), "--load-scale must be finite, got NaN");
        assert_eq!(e.render(&Python), "load_scale= must be finite, got NaN");
        let hinted = Error::Hinted { source: Box::new(e), hint: "a hint".into() };
        assert_eq!(hinted.render(&cli_flag), "--load-scale must be finite, got NaN; a hint");
    }

    /// Python's spelling as python/src/errors.rs `Keywords` writes it: the keyword, and no
    /// `allow_blowup` (no Python call takes it).
    struct Python;

    impl Spelling for Python {
        fn option(&self, key: &str, value: Option<&str>) -> Option<String> {
            (key != "allow_blowup").then(|| format!("{key}={}", value.unwrap_or("")))
        }
    }

    /// One message whose text names options, three ways: the library's own text (the keys,
    /// no control or invisible character: it is also written into files), the command
    /// line's (the flags, as the message read before it named the keys:
    /// src/simulate.rs's blow-up check), Python's (the keyword; the clause naming an option
    /// Python lacks left out), also under a stage and in a bound's problem after a file.
    #[test]
    fn a_text_names_its_options_for_each_front_end() {
        let problem = Text::new("strain 2 over the bound 0.5 (`[time] max_strain` raises it")
            .clause("; ", "allow_blowup", None, " only warns")
            .then(")");
        let e = Error::BlowUp { t: 0.5, problem }.at_stage("simulate", &"load scale 2");
        let head = "simulate at load scale 2: blow-up at t = 0.500000 s: strain 2 over the bound 0.5 (`[time] max_strain` raises it";
        assert_eq!(e.to_string(), format!("{head}; allow_blowup only warns)"));
        assert!(!e.to_string().chars().any(|c| c.is_control() || c == '\u{200b}' || c == '\u{feff}'));
        assert_eq!(e.render(&cli_flag), format!("{head}; --allow-blowup only warns)"));
        assert_eq!(e.render(&Python), format!("{head})"));
        let text = Text::new("pick one with ").option("point", Some("K"));
        let e = Error::input("s.h5", "load_scale", text).context("ignored: an input error names its file");
        assert_eq!(e.to_string(), "s.h5: load_scale: pick one with point = K");
        assert_eq!(e.render(&cli_flag), "s.h5: load_scale: pick one with --point K");
        assert_eq!(e.render(&Python), "s.h5: load_scale: pick one with point=K");
        let bound = Error::Resource(
            Text::new("over the limit; raise it with ").clause("", "max_memory", None, " or ").then("ENV"),
        );
        let e = Error::input("r.h5", "t", bound.context("its 9 entries").problem_text());
        assert_eq!(e.render(&cli_flag), "r.h5: t: its 9 entries: over the limit; raise it with --max-memory or ENV");
        assert_eq!(e.to_string(), "r.h5: t: its 9 entries: over the limit; raise it with max_memory or ENV");
    }
}
