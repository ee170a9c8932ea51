//! Lists of load scales in a pipeline file: a list, or `"A:B:N"` (also the CLI's form, which
//! takes a list as `X,Y,Z` too).

use crate::error::{Error, Result};
use serde::Deserialize;

/// A list of load scales, or `"A:B:N"`: N evenly spaced values from A to B.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Scales {
    List(Vec<f64>),
    Range(String),
}

impl Scales {
    pub fn values(&self) -> std::result::Result<Vec<f64>, String> {
        let v = match self {
            Scales::List(v) => v.clone(),
            Scales::Range(s) => parse_range(s)?,
        };
        check_scales(&v).map_err(Error::problem)?;
        Ok(v)
    }
}

/// The most load scales one range may list (each is a reduced run whose trajectory is kept
/// until the sweep file is written; the memory check in `sweep` bounds them further).
pub const MAX_LOAD_SCALES: usize = 1_000_000;

/// `"A:B:N"` → N evenly spaced values from A to B (N ≥ 1; N = 1 gives A).
pub fn parse_range(s: &str) -> std::result::Result<Vec<f64>, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if parts.len() != 3 {
        return Err(format!("`{s}` is not of the form A:B:N"));
    }
    let num = |p: &str| p.trim().parse::<f64>().map_err(|_| format!("`{p}` in `{s}` is not a number"));
    let (a, b) = (num(parts[0])?, num(parts[1])?);
    let n: usize = parts[2].trim().parse().map_err(|_| format!("`{}` in `{s}` is not a whole number", parts[2]))?;
    if n == 0 {
        return Err(format!("`{s}` asks for no load scales (N = 0)"));
    }
    if n > MAX_LOAD_SCALES {
        return Err(format!("`{s}` asks for {n} load scales, more than the {MAX_LOAD_SCALES} one sweep takes; split the range into several sweeps"));
    }
    let v = if n == 1 { vec![a] } else { (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect() };
    check_scales(&v).map_err(Error::problem)?;
    Ok(v)
}

/// `"A:B:N"` ([`parse_range`]) or a list `"X,Y,Z"` of load scales (the command line's
/// `--load-scales`; a pipeline file writes its list as a TOML array).
pub fn parse_scales(s: &str) -> std::result::Result<Vec<f64>, String> {
    if s.contains(':') {
        return parse_range(s);
    }
    let v = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| format!("`{}` in `{s}` is not a number (give A:B:N or a list X,Y,Z)", x.trim()))
        })
        .collect::<std::result::Result<Vec<f64>, String>>()?;
    if v.len() > MAX_LOAD_SCALES {
        return Err(format!("`{s}` lists {} load scales, more than the {MAX_LOAD_SCALES} one sweep takes", v.len()));
    }
    check_scales(&v).map_err(Error::problem)?;
    Ok(v)
}

/// Refuses an empty list of load scales and one that is not finite (a usage error the
/// caller puts after the field or the option; the parsers here, which `clap` and serde call
/// with `String` errors, take its [`Error::problem`]).
pub(super) fn check_scales(v: &[f64]) -> Result<()> {
    if v.is_empty() {
        return Err(Error::usage("the list of load scales is empty"));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(Error::usage(format!("load scale {x} is not finite")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The command line's two forms: `A:B:N` (N values, both ends included) and a list;
    /// anything else names the part that is not a number.
    #[test]
    fn a_range_or_a_list_of_load_scales() {
        assert_eq!(parse_scales("0.5:1.5:3").unwrap(), [0.5, 1.0, 1.5]);
        assert_eq!(parse_scales("0.3, 0.5,1.7").unwrap(), [0.3, 0.5, 1.7]);
        assert_eq!(parse_scales("-1.2").unwrap(), [-1.2]);
        let e = parse_scales("0.5,x").unwrap_err();
        assert!(e.contains("`x` in `0.5,x` is not a number") && e.contains("A:B:N or a list"), "{e}");
        assert!(parse_scales("0.5:1.0").unwrap_err().contains("is not of the form A:B:N"));
        assert!(parse_scales("0.5,inf").unwrap_err().contains("not finite"));
        assert!(parse_scales("").is_err());
    }
}
