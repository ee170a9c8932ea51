//! scratch experiment (not committed): corrected vs defects raw estimates per fifth across loads
use flexrom::pipeline::config::parse_range;
use flexrom::pipeline::estimate::{EstimateMethod, EstimatingRunner};
use flexrom::pipeline::online::{load_basis, Output};
use flexrom::pipeline::Pipeline;
use flexrom::simulate::{simulate, Overrides};

fn main() -> flexrom::Result<()> {
    flexrom::single_threaded_blas();
    let args: Vec<String> = std::env::args().collect();
    let p = Pipeline::load(&args[1])?;
    let loads = parse_range(&args[2]).expect("A:B:N");
    let with_full = args.len() > 3;
    let stored = load_basis(&p, &p.basis_path)?;
    let mut est_c = flexrom::io::estimator_file::read_estimator(&p.basis_path, &stored.basis)?.expect("estimator");
    est_c.method = EstimateMethod::Corrected;
    let mut est_d = est_c.clone();
    est_d.method = EstimateMethod::Defects;
    let mut rc = EstimatingRunner::new(&p.model, &stored.basis, Some(&est_c))?;
    let mut rd = EstimatingRunner::new(&p.model, &stored.basis, Some(&est_d))?;
    for &x in &loads {
        let (rom, ec) = rc.run(x, Output::Full)?;
        let (_, ed) = rd.run(x, Output::Full)?;
        let (ec, ed) = (ec.unwrap(), ed.unwrap());
        let err = if with_full {
            let full = simulate(&p.model, &Overrides { load_scale: Some(x), ..Default::default() })?;
            flexrom::pipeline::estimate::rel_error_by_time(&rom.result.q, &full.q)
        } else {
            vec![f64::NAN; 5]
        };
        let ratio: Vec<String> = (0..5).map(|i| format!("{:.3}", ec.by_time[i] / ed.by_time[i])).collect();
        println!(
            "{x:.4} corr {:?} def {:?} ratio {:?} err {:?} costs c {:.0}% d {:.0}%",
            ec.by_time.iter().map(|v| format!("{v:.2e}")).collect::<Vec<_>>(),
            ed.by_time.iter().map(|v| format!("{v:.2e}")).collect::<Vec<_>>(),
            ratio,
            err.iter().map(|v| format!("{v:.2e}")).collect::<Vec<_>>(),
            100.0 * ec.seconds / rom.result.wall_seconds,
            100.0 * ed.seconds / rom.result.wall_seconds
        );
    }
    Ok(())
}
