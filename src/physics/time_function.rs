//! Scalar functions of time that drive loads (model files name them with `type = ...`).

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeFunction {
    /// `f(t) = value`
    Constant { value: f64 },
    /// `f(t) = amplitude · sin(2π · frequency · t + phase)`, frequency in Hz, phase in rad.
    Sine {
        amplitude: f64,
        frequency: f64,
        #[serde(default)]
        phase: f64,
    },
    /// `f(t) = amplitude · exp(rate · t)`
    Exponential { amplitude: f64, rate: f64 },
    /// `f(t) = amplitude · min(t / duration, 1)`: a ramp that then holds.
    Ramp { amplitude: f64, duration: f64 },
    /// The first piece whose `until` is ≥ t applies; the last piece has no `until`.
    Piecewise { pieces: Vec<Piece> },
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Piece {
    pub until: Option<f64>,
    pub function: TimeFunction,
}

impl TimeFunction {
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            TimeFunction::Constant { value } => *value,
            TimeFunction::Sine { amplitude, frequency, phase } => {
                amplitude * (2.0 * std::f64::consts::PI * frequency * t + phase).sin()
            }
            TimeFunction::Exponential { amplitude, rate } => amplitude * (rate * t).exp(),
            TimeFunction::Ramp { amplitude, duration } => amplitude * (t / duration).min(1.0),
            TimeFunction::Piecewise { pieces } => pieces
                .iter()
                .find(|p| p.until.is_none_or(|u| t <= u))
                .or(pieces.last())
                .map_or(0.0, |p| p.function.eval(t)),
        }
    }

    /// Checks that every number is finite and the pieces are ordered; returns the problem.
    pub fn check(&self) -> Result<(), String> {
        let finite =
            |name: &str, v: f64| if v.is_finite() { Ok(()) } else { Err(format!("{name} must be finite, got {v}")) };
        match self {
            TimeFunction::Constant { value } => finite("value", *value),
            TimeFunction::Sine { amplitude, frequency, phase } => {
                finite("amplitude", *amplitude)?;
                finite("frequency", *frequency)?;
                finite("phase", *phase)
            }
            TimeFunction::Exponential { amplitude, rate } => {
                finite("amplitude", *amplitude)?;
                finite("rate", *rate)
            }
            TimeFunction::Ramp { amplitude, duration } => {
                finite("amplitude", *amplitude)?;
                if !(duration.is_finite() && *duration > 0.0) {
                    return Err(format!("duration must be positive and finite, got {duration}"));
                }
                Ok(())
            }
            TimeFunction::Piecewise { pieces } => {
                if pieces.is_empty() {
                    return Err("pieces must not be empty".into());
                }
                let mut last = f64::NEG_INFINITY;
                for (i, p) in pieces.iter().enumerate() {
                    match p.until {
                        Some(u) if !u.is_finite() || u <= last => {
                            return Err(format!("pieces[{i}].until must be finite and increasing, got {u}"))
                        }
                        Some(u) => last = u,
                        None if i + 1 != pieces.len() => {
                            return Err(format!("pieces[{i}] has no `until` but is not the last piece"))
                        }
                        None => {}
                    }
                    p.function.check().map_err(|e| format!("pieces[{i}].function: {e}"))?;
                }
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_crank_moment_is_continuous_at_the_switch() {
        // SPEC §4: 10 sin(3πt) for t ≤ 0.2778, 465.9 exp(−16.32 t) after; "the two branches
        // meet with equal value" — both are ≈ 4.97 at the switch (to the 4 digits given).
        let f: TimeFunction = toml::from_str(
            r#"type = "piecewise"
            [[pieces]]
            until = 0.2778
            function = { type = "sine", amplitude = 10.0, frequency = 1.5 }
            [[pieces]]
            function = { type = "exponential", amplitude = 465.9, rate = -16.32 }"#,
        )
        .unwrap();
        f.check().unwrap();
        let (a, b) = (f.eval(0.2778), f.eval(0.2778 + 1e-12));
        assert!((a - b).abs() < 1e-2 * a.abs(), "{a} vs {b}");
        assert!((f.eval(0.1) - 10.0 * (0.3 * std::f64::consts::PI).sin()).abs() < 1e-12);
    }

    #[test]
    fn unknown_keys_are_refused() {
        let r: Result<TimeFunction, _> = toml::from_str("type = \"constant\"\nvalue = 1.0\nvalu = 2.0");
        assert!(r.is_err());
    }
}
