//! Scalar functions of time that drive loads (model files name them with `type = ...`).

use crate::error::{Error, Result};
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
    /// `f(t) = c₀ + c₁ t + c₂ t² + …`
    Polynomial { coefficients: Vec<f64> },
    /// `f(t) = Σ_k f_k(t)`: smooth starts such as the spin-up profile are sums of a
    /// polynomial, a sine and a constant
    Sum { terms: Vec<TimeFunction> },
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
            // Horner's rule from the highest coefficient
            TimeFunction::Polynomial { coefficients } => coefficients.iter().rev().fold(0.0, |acc, c| acc * t + c),
            TimeFunction::Sum { terms } => terms.iter().map(|f| f.eval(t)).sum(),
        }
    }

    /// The `order`-th time derivative `f⁽ᵏ⁾(t)` (`order` 0 is [`Self::eval`]), in closed form:
    /// what a prescribed motion's velocity and acceleration levels need. A ramp's kink and a
    /// piecewise function's switch take the derivative of the piece that applies at `t` (the
    /// left one at the switch, as [`Self::eval`] does).
    pub fn derivative(&self, t: f64, order: u32) -> f64 {
        if order == 0 {
            return self.eval(t);
        }
        let tau = 2.0 * std::f64::consts::PI;
        match self {
            TimeFunction::Constant { .. } => 0.0,
            TimeFunction::Sine { amplitude, frequency, phase } => {
                // each derivative multiplies by ω and advances the phase by π/2
                let w = tau * frequency;
                let turn = f64::from(order) * std::f64::consts::FRAC_PI_2;
                amplitude * w.powi(order as i32) * (w * t + phase + turn).sin()
            }
            TimeFunction::Exponential { amplitude, rate } => amplitude * rate.powi(order as i32) * (rate * t).exp(),
            TimeFunction::Ramp { amplitude, duration } => {
                if order == 1 && t < *duration {
                    amplitude / duration
                } else {
                    0.0
                }
            }
            TimeFunction::Piecewise { pieces } => pieces
                .iter()
                .find(|p| p.until.is_none_or(|u| t <= u))
                .or(pieces.last())
                .map_or(0.0, |p| p.function.derivative(t, order)),
            TimeFunction::Polynomial { coefficients } => {
                // the derivative's coefficients k!/(k − order)! c_k, then Horner's rule
                let k0 = order as usize;
                coefficients.iter().enumerate().skip(k0).rev().fold(0.0, |acc, (k, c)| {
                    let falling: f64 = (k + 1 - k0..=k).map(|j| j as f64).product();
                    acc * t + falling * c
                })
            }
            TimeFunction::Sum { terms } => terms.iter().map(|f| f.derivative(t, order)).sum(),
        }
    }

    /// The highest frequency (Hz) of the sines in it (through pieces and sums); 0 where it
    /// has none. What a time step must resolve of it: its other kinds have no period.
    pub fn highest_frequency(&self) -> f64 {
        match self {
            TimeFunction::Sine { frequency, .. } => frequency.abs(),
            TimeFunction::Piecewise { pieces } => {
                pieces.iter().map(|p| p.function.highest_frequency()).fold(0.0, f64::max)
            }
            TimeFunction::Sum { terms } => terms.iter().map(TimeFunction::highest_frequency).fold(0.0, f64::max),
            _ => 0.0,
        }
    }

    /// Checks that every number is finite and the pieces are ordered; returns the problem.
    pub fn check(&self) -> Result<()> {
        let finite = |name: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(Error::usage(format!("{name} must be finite, got {v}")))
            }
        };
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
                    return Err(Error::usage(format!("duration must be positive and finite, got {duration}")));
                }
                Ok(())
            }
            TimeFunction::Piecewise { pieces } => {
                if pieces.is_empty() {
                    return Err(Error::usage("pieces must not be empty"));
                }
                let mut last = f64::NEG_INFINITY;
                for (i, p) in pieces.iter().enumerate() {
                    match p.until {
                        Some(u) if !u.is_finite() || u <= last => {
                            return Err(Error::usage(format!(
                                "pieces[{i}].until must be finite and increasing, got {u}"
                            )))
                        }
                        Some(u) => last = u,
                        None if i + 1 != pieces.len() => {
                            return Err(Error::usage(format!("pieces[{i}] has no `until` but is not the last piece")))
                        }
                        None => {}
                    }
                    p.function.check().map_err(|e| Error::usage(format!("pieces[{i}].function: {e}")))?;
                }
                Ok(())
            }
            TimeFunction::Polynomial { coefficients } => {
                if coefficients.is_empty() {
                    return Err(Error::usage("coefficients must not be empty (give [c0, c1, ...])"));
                }
                coefficients.iter().enumerate().try_for_each(|(i, c)| finite(&format!("coefficients[{i}]"), *c))
            }
            TimeFunction::Sum { terms } => {
                if terms.is_empty() {
                    return Err(Error::usage("terms must not be empty"));
                }
                for (i, f) in terms.iter().enumerate() {
                    f.check().map_err(|e| Error::usage(format!("terms[{i}]: {e}")))?;
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

    /// Simo and Vu-Quoc's spin-up profile (SPEC §6, issue's syntax), ωs = 4 rad/s, Ts = 15 s:
    /// θ(t) = (ωs/Ts)(t²/2 + (Ts/2π)²(cos 2πt/Ts − 1)) for t ≤ Ts, then ωs(t − Ts/2), written
    /// as a piecewise of a sum (polynomial, sine at phase π/2 for the cosine, constant) and a
    /// polynomial; the two pieces meet with equal value and rate at Ts (θ = ωs Ts/2, θ' = ωs).
    #[test]
    fn the_spin_up_profile_is_written_with_polynomials_and_sums() {
        let (ws, ts) = (4.0_f64, 15.0_f64);
        let a = (ws / ts) * (ts / (2.0 * std::f64::consts::PI)).powi(2);
        let text = format!(
            r#"type = "piecewise"
            [[pieces]]
            until = {ts}
            function = {{ type = "sum", terms = [
                {{ type = "polynomial", coefficients = [0.0, 0.0, {c2}] }},
                {{ type = "sine", amplitude = {a}, frequency = {f}, phase = {p} }},
                {{ type = "constant", value = {m} }} ] }}
            [[pieces]]
            function = {{ type = "polynomial", coefficients = [{d0}, {ws}] }}"#,
            c2 = ws / (2.0 * ts),
            f = 1.0 / ts,
            p = std::f64::consts::FRAC_PI_2,
            m = -a,
            d0 = -ws * ts / 2.0,
        );
        let f: TimeFunction = toml::from_str(&text).unwrap();
        f.check().unwrap();
        let exact = |t: f64| {
            if t <= ts {
                (ws / ts)
                    * (t * t / 2.0
                        + (ts / (2.0 * std::f64::consts::PI)).powi(2)
                            * ((2.0 * std::f64::consts::PI * t / ts).cos() - 1.0))
            } else {
                ws * (t - ts / 2.0)
            }
        };
        for t in [0.0, 1.0, 7.5, 14.9, 15.0, 20.0] {
            assert!(
                (f.eval(t) - exact(t)).abs() < 1e-12 * (1.0 + exact(t).abs()),
                "t = {t}: {} vs {}",
                f.eval(t),
                exact(t)
            );
        }
        let h = 1e-6;
        let rate = |t: f64| (f.eval(t + h) - f.eval(t - h)) / (2.0 * h);
        assert!((f.eval(ts) - ws * ts / 2.0).abs() < 1e-12 * ws * ts);
        assert!(
            (rate(ts - 1e-3) - ws).abs() < 1e-5 && (rate(ts + 1e-3) - ws).abs() < 1e-6,
            "{} {}",
            rate(ts - 1e-3),
            rate(ts + 1e-3)
        );
        // and it starts at rest: θ(0) = 0, θ'(0) = 0
        assert!(f.eval(0.0).abs() < 1e-15 && rate(1e-3).abs() < 1e-5);
    }

    /// Every kind's first and second derivatives against central differences of `eval`
    /// (step 1e-4: truncation O(h²) ≈ 1e-8 relative, round-off ≈ 1e-16/h² ≈ 1e-8 on the
    /// second; bounds 1e-6 and 1e-4 relative to the function's scale), away from kinks.
    #[test]
    fn derivatives_match_finite_differences() {
        let fs: Vec<TimeFunction> = [
            "type = \"constant\"\nvalue = 2.0",
            "type = \"sine\"\namplitude = 0.3\nfrequency = 1.7\nphase = 0.4",
            "type = \"exponential\"\namplitude = 2.0\nrate = -1.3",
            "type = \"ramp\"\namplitude = 3.0\nduration = 2.0",
            "type = \"polynomial\"\ncoefficients = [1.0, -2.0, 0.5, 0.25]",
            "type = \"sum\"\nterms = [{ type = \"polynomial\", coefficients = [0.0, 150.0] }, \
             { type = \"sine\", amplitude = 1.0, frequency = 0.5 }]",
        ]
        .iter()
        .map(|s| toml::from_str(s).unwrap())
        .collect();
        let h = 1e-4;
        for f in &fs {
            for t in [0.3, 1.1, 2.7] {
                let d1 = (f.eval(t + h) - f.eval(t - h)) / (2.0 * h);
                let d2 = (f.eval(t + h) - 2.0 * f.eval(t) + f.eval(t - h)) / (h * h);
                let scale = 1.0 + f.eval(t).abs() + f.derivative(t, 1).abs() + f.derivative(t, 2).abs();
                assert!((f.derivative(t, 1) - d1).abs() < 1e-6 * scale, "{f:?} at {t}: {} vs {d1}", f.derivative(t, 1));
                assert!((f.derivative(t, 2) - d2).abs() < 1e-4 * scale, "{f:?} at {t}: {} vs {d2}", f.derivative(t, 2));
            }
        }
        // p = 1 − 2t + t²/2 + t³/4 at t = 2: p' = −2 + t + 3t²/4 = 3, p'' = 1 + 3t/2 = 4, p''' = 3/2
        let p = &fs[4];
        assert_eq!((p.derivative(2.0, 1), p.derivative(2.0, 2), p.derivative(2.0, 3)), (3.0, 4.0, 1.5));
    }

    #[test]
    fn empty_polynomials_and_sums_are_refused() {
        let p: TimeFunction = toml::from_str("type = \"polynomial\"\ncoefficients = []").unwrap();
        assert!(p.check().unwrap_err().to_string().contains("coefficients"));
        let s: TimeFunction = toml::from_str("type = \"sum\"\nterms = []").unwrap();
        assert!(s.check().unwrap_err().to_string().contains("terms"));
        let bad: TimeFunction = toml::from_str("type = \"polynomial\"\ncoefficients = [1.0, nan]").unwrap();
        assert!(bad.check().unwrap_err().to_string().contains("coefficients[1]"));
    }

    #[test]
    fn unknown_keys_are_refused() {
        let r: std::result::Result<TimeFunction, _> = toml::from_str("type = \"constant\"\nvalue = 1.0\nvalu = 2.0");
        assert!(r.is_err());
    }
}
