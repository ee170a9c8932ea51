//! Lists of load scales in a pipeline file: a list, or `"A:B:N"` (also the CLI's form).

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
        check_scales(&v)?;
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
    check_scales(&v)?;
    Ok(v)
}

pub(super) fn check_scales(v: &[f64]) -> std::result::Result<(), String> {
    if v.is_empty() {
        return Err("the list of load scales is empty".into());
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("load scale {x} is not finite"));
    }
    Ok(())
}
