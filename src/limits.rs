//! Resource bounds checked before anything large is allocated, and the switch that turns
//! blow-up errors into warnings. They belong to a loaded model (`Model::load_with`), not
//! to the process: the command line gives them (`--max-memory`, `--max-steps`,
//! `--max-elements`, `--allow-blowup`); a library caller passes its own, or takes the
//! environment's (`FLEXROM_MAX_MEMORY`, `FLEXROM_MAX_STEPS`, `FLEXROM_MAX_ELEMENTS`) and
//! the defaults with [`Limits::from_env_or_defaults`]: half of the machine's memory
//! (`MemTotal` in /proc/meminfo, 4 GiB when unreadable), 10⁷ time steps and 2·10⁵ elements.
//!
//! Estimates count only the big arrays a stage keeps (8 bytes per f64):
//!
//! ```text
//!     full run      (n_t) (2 n_dof + n_c + n_pv + 1) · 8  +  n_el · 2 KiB (system, banded KKT)
//!                   (q and q̇; n_pv: the probes' values, 2 each plus 1 per strain or curvature)
//!     dense LU      n_kkt² · 8 · 2                               (n_kkt = n_dof + n_c)
//!     training      Σ runs + 3 · n_dof · n_snapshots · 8          (snapshot matrix, POD copies)
//!     sweep         N · n_t · (r + n_pv) · 8  (+ N · n_t · n_dof · 8 with --validate)
//! ```

use crate::error::{show_number, Error, Result, Text};

/// The bounds in force.
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// bytes a stage may allocate for its big arrays
    pub max_memory: u64,
    /// where `max_memory` came from, for messages
    pub memory_source: String,
    /// time steps a run may take
    pub max_steps: u64,
    /// elements a model may have, over all bodies (the full model's cost per step grows
    /// with them; 10⁵ elements already take minutes per step to set up)
    pub max_elements: u64,
    /// blow-up checks warn instead of failing
    pub allow_blowup: bool,
}

/// Bytes assumed per element for the assembled system (element lists, 8×8 blocks, the
/// banded KKT storage of bandwidth ~12 for each of the element's 4 coordinates).
pub const BYTES_PER_ELEMENT: f64 = 2048.0;
pub const DEFAULT_MAX_STEPS: u64 = 10_000_000;
pub const DEFAULT_MAX_ELEMENTS: u64 = 200_000;

impl Limits {
    /// The environment's bounds, else the defaults (a malformed variable counts as unset:
    /// only the command line reports it, through [`from_env`]).
    pub fn from_env_or_defaults() -> Limits {
        from_env(None, None, None, false).unwrap_or_else(|_| defaults())
    }
}

fn defaults() -> Limits {
    let (max_memory, memory_source) = default_memory();
    Limits {
        max_memory,
        memory_source,
        max_steps: DEFAULT_MAX_STEPS,
        max_elements: DEFAULT_MAX_ELEMENTS,
        allow_blowup: false,
    }
}

fn default_memory() -> (u64, String) {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines().find(|l| l.starts_with("MemTotal:")).and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
    });
    match total {
        Some(kib) => (kib.saturating_mul(1024) / 2, "half of MemTotal".into()),
        None => (4 << 30, "the default 4 GiB".into()),
    }
}

/// The bounds from the command-line values (`None`: not given), else the environment,
/// else the defaults. A malformed value is a usage error naming the option.
pub fn from_env(
    max_memory: Option<&str>,
    max_steps: Option<&str>,
    max_elements: Option<&str>,
    allow_blowup: bool,
) -> Result<Limits> {
    let mut l = defaults();
    l.allow_blowup = allow_blowup;
    let env_mem = std::env::var("FLEXROM_MAX_MEMORY").ok();
    if let Some((v, name)) =
        max_memory.map(|v| (v.to_string(), "--max-memory")).or(env_mem.map(|v| (v, "FLEXROM_MAX_MEMORY")))
    {
        l.max_memory = parse_bytes(&v).map_err(|e| Error::usage(format!("{name}: {e}")))?;
        l.memory_source = name.to_string();
    }
    let env_steps = std::env::var("FLEXROM_MAX_STEPS").ok();
    if let Some((v, name)) =
        max_steps.map(|v| (v.to_string(), "--max-steps")).or(env_steps.map(|v| (v, "FLEXROM_MAX_STEPS")))
    {
        l.max_steps = positive_count(&v, name)?;
    }
    let env_el = std::env::var("FLEXROM_MAX_ELEMENTS").ok();
    if let Some((v, name)) =
        max_elements.map(|v| (v.to_string(), "--max-elements")).or(env_el.map(|v| (v, "FLEXROM_MAX_ELEMENTS")))
    {
        l.max_elements = positive_count(&v, name)?;
    }
    Ok(l)
}

fn positive_count(v: &str, name: &str) -> Result<u64> {
    v.trim()
        .parse::<u64>()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| Error::usage(format!("{name}: `{v}` is not a positive whole number")))
}

/// `"8G"`, `"512M"`, `"1.5GiB"`, `"1000000"` → bytes (K, M, G, T are powers of 1024).
pub fn parse_bytes(s: &str) -> Result<u64> {
    let t = s.trim();
    let split = t.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let x: f64 =
        num.trim().parse().map_err(|_| Error::usage(format!("`{s}` is not a size (e.g. 8G, 512M, 1000000)")))?;
    let mult = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 1.0,
        "K" | "KB" | "KIB" => 1024.0,
        "M" | "MB" | "MIB" => 1024.0 * 1024.0,
        "G" | "GB" | "GIB" => 1024.0 * 1024.0 * 1024.0,
        "T" | "TB" | "TIB" => 1024.0_f64.powi(4),
        u => return Err(Error::usage(format!("unknown unit `{u}` in `{s}` (use K, M, G or T)"))),
    };
    let b = x * mult;
    if !(b.is_finite() && (1.0..1.8e19).contains(&b)) {
        return Err(Error::usage(format!("`{s}` is not a positive size below 16 EiB")));
    }
    Ok(b as u64)
}

/// Human-readable bytes.
pub fn show_bytes(b: f64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut x = b;
    let mut u = 0;
    while x >= 1024.0 && u + 1 < UNITS.len() {
        x /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{x:.0} {}", UNITS[0])
    } else {
        format!("{x:.1} {}", UNITS[u])
    }
}

impl Limits {
    /// Refuses an allocation estimated at `bytes` (computed in f64, so it cannot overflow)
    /// above the memory bound; `what` says what it is for.
    pub fn check_memory(&self, what: &str, bytes: f64) -> Result<()> {
        let l = self;
        if bytes.is_finite() && bytes <= l.max_memory as f64 {
            return Ok(());
        }
        let over = format!(
            "{what} would need about {} of memory, over the limit of {} ({}); raise it with ",
            show_bytes(bytes),
            show_bytes(l.max_memory as f64),
            l.memory_source
        );
        Err(Error::Resource(
            raise_with(over, "max_memory", "FLEXROM_MAX_MEMORY").then(", or use fewer steps, elements or load scales"),
        ))
    }

    /// Refuses a model of `n` elements above the element bound.
    pub fn check_elements(&self, n: f64) -> Result<()> {
        let l = self;
        if n <= l.max_elements as f64 {
            return Ok(());
        }
        let over = format!("{n:.0} elements in all, over the limit of {} (raise it with ", l.max_elements);
        Err(Error::Resource(raise_with(over, "max_elements", "FLEXROM_MAX_ELEMENTS").then(")")))
    }

    /// Refuses a run of `steps` (a float, so 1e300 / 1e-300 cannot overflow) above the step bound.
    pub fn check_steps(&self, steps: f64, dt: f64, t_end: f64) -> Result<()> {
        let l = self;
        if steps.is_finite() && steps <= l.max_steps as f64 {
            return Ok(());
        }
        let over = format!(
            "t_end = {} s at dt = {} s is {steps:.3e} steps, over the limit of {} steps; raise it with ",
            show_number(t_end),
            show_number(dt),
            l.max_steps
        );
        Err(Error::Resource(raise_with(over, "max_steps", "FLEXROM_MAX_STEPS").then(", or use a larger dt")))
    }
}

/// `over`, then the option `key` or the environment variable `env` that raises the bound
/// (`--max-memory or FLEXROM_MAX_MEMORY` on the command line; a front end without the
/// option names the variable alone).
fn raise_with(over: String, key: &'static str, env: &str) -> Text {
    Text::new(over).clause("", key, None, " or ").then(env)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::{cli_flag, Spelling};

    /// A front end without the bounds' options (Python reads the environment variables).
    struct NoBoundOptions;

    impl Spelling for NoBoundOptions {
        fn option(&self, _: &str, _: Option<&str>) -> Option<String> {
            None
        }
    }

    /// Each bound names the option that raises it by its key; the command line's text is
    /// byte for byte the one it showed when these messages wrote its flags (the literals
    /// below are those messages' earlier format strings filled in; docs/guarantees-robust.md
    /// quotes the memory one), and a front end without the options names the variable alone.
    #[test]
    fn a_bound_names_the_option_and_the_variable_that_raise_it() {
        let l = Limits {
            max_memory: 1024,
            memory_source: "FLEXROM_MAX_MEMORY".into(),
            max_steps: 10,
            max_elements: 5,
            allow_blowup: false,
        };
        let e = l.check_memory("a full run", 2048.0).unwrap_err();
        let head = "a full run would need about 2.0 KiB of memory, over the limit of 1.0 KiB (FLEXROM_MAX_MEMORY); raise it with";
        let tail = "FLEXROM_MAX_MEMORY, or use fewer steps, elements or load scales";
        assert_eq!(e.render(&cli_flag), format!("{head} --max-memory or {tail}"));
        assert_eq!(e.to_string(), format!("{head} max_memory or {tail}"));
        assert_eq!(e.render(&NoBoundOptions), format!("{head} {tail}"));
        let e = l.check_steps(100.0, 0.01, 1.0).unwrap_err();
        assert_eq!(
            e.render(&cli_flag),
            "t_end = 1 s at dt = 0.01 s is 1.000e2 steps, over the limit of 10 steps; raise it with --max-steps or FLEXROM_MAX_STEPS, or use a larger dt"
        );
        let e = l.check_elements(6.0).unwrap_err();
        assert_eq!(
            e.render(&cli_flag),
            "6 elements in all, over the limit of 5 (raise it with --max-elements or FLEXROM_MAX_ELEMENTS)"
        );
        assert_eq!(
            e.render(&NoBoundOptions),
            "6 elements in all, over the limit of 5 (raise it with FLEXROM_MAX_ELEMENTS)"
        );
    }

    #[test]
    fn sizes_parse_with_binary_units_and_refuse_nonsense() {
        assert_eq!(parse_bytes("1000").unwrap(), 1000);
        assert_eq!(parse_bytes("2K").unwrap(), 2048);
        assert_eq!(parse_bytes("1.5GiB").unwrap(), 3 << 29);
        assert_eq!(parse_bytes(" 8 g ").unwrap(), 8 << 30);
        for bad in ["", "x", "-1G", "0", "nan", "inf", "1e300", "3Q"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }
}
