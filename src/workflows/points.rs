//! The points a sweep runs at when they are more than a line of load scales: a grid of
//! axes (`--param NAME=A:B:N[:log]`, `--load-scales A:B:N`), the first axis slowest, or a
//! list read from a CSV file (`--points FILE`: a header of parameter names, one point per
//! row).

use crate::error::{Error, Result};
use crate::pipeline::config::{parse_range, MAX_LOAD_SCALES};
use crate::solver::parameters::Parameters;
use std::path::Path;

/// One axis of a grid from `NAME=X`, `NAME=A:B:N` (evenly spaced) or `NAME=A:B:N:log`
/// (evenly in the logarithm, `A`, `B` > 0).
pub fn parse_axis(spec: &str) -> std::result::Result<(String, Vec<f64>), String> {
    let (name, values) = spec.split_once('=').ok_or_else(|| format!("`{spec}` is not NAME=A:B:N (or NAME=X)"))?;
    let (name, values) = (name.trim().to_string(), values.trim());
    if !crate::solver::parameters::is_parameter_name(&name) {
        return Err(format!("`{spec}` is not NAME=A:B:N (a name is letters, digits and `_`, starting with a letter)"));
    }
    let axis = if let Some(linear) = values.strip_suffix(":log") {
        let v = parse_range(linear)?;
        // the ends as written (the linear range's last value may differ from B in the last bit)
        let b: f64 = linear.split(':').nth(1).and_then(|x| x.trim().parse().ok()).unwrap_or(v[v.len() - 1]);
        let a = v[0];
        if !(a > 0.0 && b > 0.0) {
            return Err(format!("`{values}`: a logarithmic axis needs A and B above zero"));
        }
        let n = v.len();
        if n == 1 {
            vec![a]
        } else {
            // the ends exactly as given (a point of a file or a later grid then matches them)
            (0..n).map(|i| if i + 1 == n { b } else { a * (b / a).powf(i as f64 / (n - 1) as f64) }).collect()
        }
    } else if values.contains(':') {
        parse_range(values)?
    } else {
        let x: f64 = values.parse().map_err(|_| format!("`{values}` (parameter {name}) is not a number or A:B:N"))?;
        if !x.is_finite() {
            return Err(format!("parameter {name} must be finite, got {x}"));
        }
        vec![x]
    };
    Ok((name, axis))
}

/// Every combination of the axes' values, the first axis slowest (row-major: a 5 × 3 grid
/// of `drive` and `E` runs drive's first value with E's three, then its second, …).
/// Refuses an axis named twice and a grid of more than [`MAX_LOAD_SCALES`] points.
pub fn grid(axes: &[(String, Vec<f64>)]) -> Result<Vec<Parameters>> {
    for (i, (name, _)) in axes.iter().enumerate() {
        if axes[..i].iter().any(|(n, _)| n == name) {
            return Err(if name == crate::solver::parameters::LOAD_SCALE {
                Error::option("load_scales", None, "and the parameter load_scale both give the load scales")
            } else {
                Error::option("param", Some(name.clone()), "given twice")
            });
        }
    }
    let total = axes.iter().map(|(_, v)| v.len() as f64).product::<f64>();
    if total > MAX_LOAD_SCALES as f64 {
        return Err(Error::usage(format!(
            "the grid has {total} points, more than the {MAX_LOAD_SCALES} one sweep takes; split it into several sweeps"
        )));
    }
    let mut points = vec![Parameters::default()];
    for (name, values) in axes {
        points = points.iter().flat_map(|mu| values.iter().map(move |&v| mu.clone().with(name, v))).collect();
    }
    Ok(points)
}

/// The points of a CSV file: a header of parameter names (`load_scale` for `λ`), then one
/// point per row, every value a finite number. Errors name the file, the row and the column.
pub fn read_points_csv(path: &Path) -> Result<Vec<Parameters>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut r = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(text.as_bytes());
    let bad = |field: String, problem: String| Error::input(path, field, problem);
    let names: Vec<String> = r
        .headers()
        .map_err(|e| bad("header".into(), format!("cannot be read: {e}")))?
        .iter()
        .map(str::to_string)
        .collect();
    if names.is_empty() || names.iter().any(String::is_empty) {
        return Err(bad("header".into(), "must name every column's parameter (e.g. `drive,E_lower`)".into()));
    }
    if let Some(n) = names.iter().find(|n| !crate::solver::parameters::is_parameter_name(n)) {
        return Err(bad(
            "header".into(),
            format!("`{n}` is not a parameter name (letters, digits and `_`, starting with a letter); columns are separated by commas"),
        ));
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(bad("header".into(), format!("names `{n}` twice")));
        }
    }
    let mut points = Vec::new();
    for (k, rec) in r.records().enumerate() {
        let row = k + 2;
        let rec = rec.map_err(|e| bad(format!("row {row}"), format!("cannot be read: {e}")))?;
        if rec.len() != names.len() {
            return Err(bad(format!("row {row}"), format!("has {} values for {} columns", rec.len(), names.len())));
        }
        let mut mu = Parameters::default();
        for (name, value) in names.iter().zip(rec.iter()) {
            let x: f64 =
                value.parse().ok().filter(|x: &f64| x.is_finite()).ok_or_else(|| {
                    bad(format!("row {row}, column {name}"), format!("`{value}` is not a finite number"))
                })?;
            mu = mu.with(name, x);
        }
        points.push(mu);
    }
    if points.is_empty() {
        return Err(bad("(file)".into(), "holds no point (a header and at least one row)".into()));
    }
    if points.len() > MAX_LOAD_SCALES {
        return Err(bad(
            "(file)".into(),
            format!("holds {} points, more than the {MAX_LOAD_SCALES} one sweep takes", points.len()),
        ));
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_are_linear_logarithmic_or_single_and_the_grid_runs_the_first_slowest() {
        let (name, lin) = parse_axis("drive=0.5:1.5:3").unwrap();
        assert_eq!((name.as_str(), lin.as_slice()), ("drive", [0.5, 1.0, 1.5].as_slice()));
        // log: 1e8 … 4e8 in 3 points has the geometric mean 2e8 in the middle
        let (_, log) = parse_axis("E=1e8:4e8:3:log").unwrap();
        assert_eq!((log[0], log[2]), (1e8, 4e8));
        assert_eq!(*parse_axis("p=0.2:3:4:log").unwrap().1.last().unwrap(), 3.0, "the end exactly");
        assert!((log[1] - 2e8).abs() < 1e-6 * 2e8, "{log:?}");
        assert_eq!(parse_axis("g=1.2").unwrap().1, [1.2]);
        for bad in ["g", "g=abc", "E=0:4e8:3:log", "g=1:2:0", "g=inf"] {
            assert!(parse_axis(bad).is_err(), "{bad} accepted");
        }
        let g = grid(&[("a".into(), vec![1.0, 2.0]), ("b".into(), vec![10.0, 20.0, 30.0])]).unwrap();
        let pairs: Vec<(f64, f64)> = g.iter().map(|mu| (mu.get("a").unwrap(), mu.get("b").unwrap())).collect();
        assert_eq!(pairs, [(1.0, 10.0), (1.0, 20.0), (1.0, 30.0), (2.0, 10.0), (2.0, 20.0), (2.0, 30.0)]);
        assert!(grid(&[("a".into(), vec![1.0]), ("a".into(), vec![2.0])]).is_err());
    }

    #[test]
    fn a_points_file_is_read_by_its_header_and_bad_cells_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("points.csv");
        std::fs::write(&p, "load_scale, drive\n1.0, 0.5\n1.1, 2e-1\n").unwrap();
        let pts = read_points_csv(&p).unwrap();
        assert_eq!(
            pts,
            [Parameters::load_scale(1.0).with("drive", 0.5), Parameters::load_scale(1.1).with("drive", 0.2)]
        );
        std::fs::write(&p, "drive\n0.5\nx\n").unwrap();
        let e = read_points_csv(&p).unwrap_err().to_string();
        assert!(e.contains("points.csv: row 3, column drive: `x` is not a finite number"), "{e}");
        std::fs::write(&p, "drive,drive\n0.5,1\n").unwrap();
        assert!(read_points_csv(&p).unwrap_err().to_string().contains("names `drive` twice"));
        std::fs::write(&p, "drive\n").unwrap();
        assert!(read_points_csv(&p).unwrap_err().to_string().contains("holds no point"));
        // another separator makes one column of a name no parameter can have
        std::fs::write(&p, "drive;E\n0.5;1\n").unwrap();
        let e = read_points_csv(&p).unwrap_err().to_string();
        assert!(e.contains("points.csv: header: `drive;E` is not a parameter name"), "{e}");
        assert!(parse_axis("=1:2:3").unwrap_err().contains("is not NAME=A:B:N"));
    }
}
