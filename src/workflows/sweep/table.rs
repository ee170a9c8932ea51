//! The table `flexrom sweep` prints on stdout (text form; `--csv`/`--json` use
//! `report::tables::sweep_table`).

use crate::records::sweep_outcome::{Sweep, STATUS_FAILED};

/// The table printed on stdout.
pub fn table(s: &Sweep) -> String {
    // a full sweep's runs are exact: no estimate, nothing extrapolated
    let mut out = String::from(if s.full {
        "load_scale  full_ms  newton"
    } else {
        "load_scale  rom_ms  newton  error_estimate  est_ms  extrap"
    });
    if s.validated {
        out.push_str("   rel_error  probe_err_m  full_ms  speedup");
    }
    // which model answered, where the full one stood in for the reduced one somewhere
    let fell_back = s.n_fallback() > 0;
    if fell_back {
        out.push_str("   answer");
    }
    // the named parameters of the points, where there are any, lead each line
    let named: Vec<String> =
        crate::records::sweep_file::point_names(s.scales.iter().map(|x| &x.mu)).into_iter().skip(1).collect();
    let lead = |values: Vec<String>| values.into_iter().map(|v| format!("{v}  ")).collect::<String>();
    out.insert_str(0, &lead(named.iter().map(|n| format!("{n:>10}")).collect()));
    out.push('\n');
    for x in &s.scales {
        out.push_str(&lead(named.iter().map(|n| scale(x.mu.get(n).unwrap_or(1.0))).collect()));
        let Some(p) = x.point() else {
            out.push_str(&format!(
                "{}  {}: {}\n",
                scale(x.mu.scale()),
                if x.status() == STATUS_FAILED { "failed" } else { "not run" },
                x.message()
            ));
            continue;
        };
        let r = &p.run.result;
        if s.full {
            out.push_str(&format!(
                "{}  {:>7.2}  {:>6}\n",
                scale(r.settings.mu.scale()),
                1e3 * r.wall_seconds,
                r.stats.newton_iterations
            ));
            continue;
        }
        out.push_str(&format!(
            "{}  {:>6.2}  {:>6}",
            scale(r.settings.mu.scale()),
            1e3 * r.wall_seconds,
            r.stats.newton_iterations
        ));
        match &p.estimate {
            Some(e) => out.push_str(&format!("  {:>14.3e}  {:>6.2}", e.error_estimate, 1e3 * e.seconds)),
            None => out.push_str(&format!("  {:>14}  {:>6}", "-", "-")),
        }
        out.push_str(if p.extrapolated { "     yes" } else { "      no" });
        if let Some(v) = &p.validation {
            out.push_str(&format!(
                "  {:>10.3e}  {:>11.3e}  {:>7.2}  {:>7.2}",
                v.rel_error,
                v.max_probe_error,
                1e3 * v.full_seconds,
                v.speedup
            ));
        }
        if fell_back {
            out.push_str(if p.fallback.is_some() { "     full" } else { "  reduced" });
        }
        out.push('\n');
    }
    out
}

/// A load scale in the table's first column: fixed point, or exponent form when that would
/// not fit (|x| ≥ 1e6) or show nothing (|x| < 1e-3).
fn scale(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:>10.3e}")
    } else {
        format!("{x:>10.4}")
    }
}
