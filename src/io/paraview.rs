//! ParaView's view of a result file (`--paraview` of `simulate`, `online`, `statics`): the
//! deformed centre lines at every recorded instant, sampled within the elements
//! ([`crate::physics::centre_line`], 4 points an element), stored in the result file
//!
//! ```text
//! /paraview/lines             (n_seg, 2)   the polylines' segments: indices of their two points
//! /paraview/points/<k>        (n_pts, 3)   x, y, 0 of every sample at instant k, m
//! /paraview/velocity/<k>      (n_pts, 3)   ṙ = S(ξ) q̇ there, m/s
//! /paraview/strain/<k>        (n_pts)      axial Green strain ε there, 1
//! /paraview/curvature/<k>     (n_pts)      signed curvature κ there, 1/m
//! ```
//!
//! (`<k>` = instant k of `/t`, zero-padded to 6 digits), and an XDMF 3 file beside it
//! (`out.h5` → `out.xdmf`): a temporal collection of one grid per instant, polyline
//! topology, the points as geometry, strain, curvature and velocity as point data. One
//! dataset per instant, not one `(n_t, n_pts, 3)` array read by hyperslabs: readers such as
//! meshio read only whole datasets.
//!
//! A modes file (`modes --paraview`) holds the mode shapes as ParaView draws vibration
//! modes: displacement fields on the configuration linearized at, one per mode,
//!
//! ```text
//! /paraview/lines             (n_seg, 2)   as above
//! /paraview/points            (n_pts, 3)   x, y, 0 of every sample of q*, m
//! /paraview/shapes/<k>        (n_pts, 3)   u = S(ξ) φ_k there (row k of /shapes), m/√kg
//! ```
//!
//! and an XDMF file of one grid whose vector attributes are the shapes, named by mode and
//! frequency (`mode_1 (3.512 Hz)`): ParaView's Warp By Vector on one of them draws the mode.

use crate::error::{Error, Result};
use crate::physics::centre_line::CentreLines;
use crate::physics::parts::BeamBody;
use std::path::{Path, PathBuf};

/// The group of the result file that holds ParaView's datasets.
pub const GROUP: &str = "paraview";
/// The mark in every XDMF file flexrom writes (an `Information` element): how an
/// existing `.xdmf` is recognised as flexrom's own before it is replaced.
pub const XDMF_MARK: &str = "<Information Name=\"written_by\" Value=\"flexrom\"/>";

/// The mark of a modes file's XDMF file, an XML comment: meshio's reader of a single grid
/// takes an `Information` element for field data and refuses [`XDMF_MARK`] there.
pub const XDMF_COMMENT_MARK: &str = "<!-- written_by flexrom -->";

/// What the XDMF file describes: the sizes of the datasets written.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub n_points: usize,
    pub n_segments: usize,
    pub t: Vec<f64>,
}

/// The XDMF file beside a result file: the same stem, `.xdmf`.
pub fn xdmf_path(result: &Path) -> PathBuf {
    result.with_extension("xdmf")
}

/// Refuses to write the XDMF file beside `result` where a file there is not one flexrom
/// wrote ([`XDMF_MARK`] or [`XDMF_COMMENT_MARK`]), naming it and the option.
pub fn check_xdmf_output(result: &Path) -> Result<()> {
    let x = xdmf_path(result);
    match std::fs::read_to_string(&x) {
        Err(_) if std::fs::symlink_metadata(&x).is_err() => Ok(()),
        Ok(text) if text.contains(XDMF_MARK) || text.contains(XDMF_COMMENT_MARK) => Ok(()),
        _ => Err(Error::input(
            &x,
            "--paraview",
            "exists and is not an XDMF file flexrom wrote; flexrom replaces only its own: remove it or choose another -o",
        )),
    }
}

/// Writes `/paraview` into the result file `f` from a run's coordinates `q` and rates `qd`
/// (one column per instant, `n_dof × n_t`, as the solver keeps them) at the instants `t`.
pub fn write_datasets(
    f: &hdf5::File,
    bodies: &[BeamBody],
    t: &[f64],
    q: &ndarray::Array2<f64>,
    qd: &ndarray::Array2<f64>,
) -> hdf5::Result<Layout> {
    let lines = CentreLines::new(bodies, usize::MAX);
    let g = f.create_group(GROUP)?;
    let n_segments = write_lines(&g, &lines)?;
    let groups = ["points", "velocity", "strain", "curvature"].map(|n| g.create_group(n));
    let [points, velocity, strain, curvature] = groups;
    let (points, velocity, strain, curvature) = (points?, velocity?, strain?, curvature?);
    for k in 0..t.len() {
        let (qk, vk) = (q.column(k).to_vec(), qd.column(k).to_vec());
        let name = step_name(k);
        points.new_dataset_builder().with_data(&xyz(lines.interpolate(&qk))).create(name.as_str())?;
        velocity.new_dataset_builder().with_data(&xyz(lines.interpolate(&vk))).create(name.as_str())?;
        strain.new_dataset_builder().with_data(&lines.strains(&qk)).create(name.as_str())?;
        curvature.new_dataset_builder().with_data(&lines.curvatures(&qk)).create(name.as_str())?;
    }
    Ok(Layout { n_points: lines.n_points(), n_segments, t: t.to_vec() })
}

/// Writes `/paraview/lines`: each body's consecutive samples joined; returns the number
/// of segments.
fn write_lines(g: &hdf5::Group, lines: &CentreLines) -> hdf5::Result<usize> {
    let segments: Vec<[i32; 2]> =
        lines.bodies().flat_map(|r| (r.start..r.end.saturating_sub(1)).map(|i| [i as i32, i as i32 + 1])).collect();
    let seg = ndarray::Array2::from_shape_fn((segments.len(), 2), |(i, j)| segments[i][j]);
    g.new_dataset_builder().with_data(&seg).create("lines")?;
    Ok(segments.len())
}

/// Planar points as ParaView's 3-vectors (z = 0).
fn xyz(v: Vec<[f64; 2]>) -> ndarray::Array2<f64> {
    ndarray::Array2::from_shape_fn((v.len(), 3), |(i, j)| if j < 2 { v[i][j] } else { 0.0 })
}

/// What the XDMF file of a modes file describes: the sizes of the datasets written and
/// each mode's frequency (Hz).
#[derive(Clone, Debug, PartialEq)]
pub struct ModesLayout {
    pub n_points: usize,
    pub n_segments: usize,
    pub frequencies: Vec<f64>,
}

/// Writes `/paraview` into the modes file `f`: the samples of the configuration `q` and,
/// per row `φ_k` of `shapes` (`N × n_dof`), the displacement field `u = S(ξ) φ_k` (the
/// interpolation is linear in the coordinates, so the shape's field is the interpolation
/// of the shape).
pub fn write_mode_datasets(
    f: &hdf5::File,
    bodies: &[BeamBody],
    q: &[f64],
    shapes: ndarray::ArrayView2<f64>,
    frequencies: &[f64],
) -> hdf5::Result<ModesLayout> {
    let lines = CentreLines::new(bodies, usize::MAX);
    let g = f.create_group(GROUP)?;
    let n_segments = write_lines(&g, &lines)?;
    g.new_dataset_builder().with_data(&xyz(lines.interpolate(q))).create("points")?;
    let fields = g.create_group("shapes")?;
    for (k, phi) in shapes.rows().into_iter().enumerate() {
        let u = xyz(lines.interpolate(&phi.to_vec()));
        fields.new_dataset_builder().with_data(&u).create(step_name(k).as_str())?;
    }
    Ok(ModesLayout { n_points: lines.n_points(), n_segments, frequencies: frequencies.to_vec() })
}

/// The name of mode `k` (0-based) in the XDMF file: its number from 1 and its frequency.
pub fn mode_name(k: usize, frequency: f64) -> String {
    format!("mode_{} ({frequency:.6} Hz)", k + 1)
}

/// The dataset name of instant `k`.
pub fn step_name(k: usize) -> String {
    format!("{k:06}")
}

/// The XDMF 3 text describing [`write_datasets`]' datasets in the HDF5 file named `h5`
/// (a name relative to the XDMF file's folder).
pub fn xdmf_text(h5: &str, layout: &Layout) -> String {
    let (n, s) = (layout.n_points, layout.n_segments);
    let h5 = escape(h5);
    let item = |path: String, dims: String, kind: &str| {
        format!("<DataItem Dimensions=\"{dims}\" NumberType=\"{kind}\" Precision=\"{}\" Format=\"HDF\">{h5}:/{GROUP}/{path}</DataItem>", if kind == "Int" { 4 } else { 8 })
    };
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n");
    x.push_str(&format!("    {XDMF_MARK}\n"));
    x.push_str("    <Grid Name=\"centre_lines\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (k, t) in layout.t.iter().enumerate() {
        let step = step_name(k);
        x.push_str(&format!("      <Grid Name=\"t{step}\" GridType=\"Uniform\">\n"));
        x.push_str(&format!("        <Time Value=\"{t:e}\"/>\n"));
        x.push_str(&format!(
            "        <Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"{s}\">\n          {}\n        </Topology>\n",
            item("lines".into(), format!("{s} 2"), "Int")
        ));
        x.push_str(&format!(
            "        <Geometry GeometryType=\"XYZ\">\n          {}\n        </Geometry>\n",
            item(format!("points/{step}"), format!("{n} 3"), "Float")
        ));
        for (name, kind, dims) in [
            ("strain", "Scalar", format!("{n}")),
            ("curvature", "Scalar", format!("{n}")),
            ("velocity", "Vector", format!("{n} 3")),
        ] {
            x.push_str(&format!(
                "        <Attribute Name=\"{name}\" AttributeType=\"{kind}\" Center=\"Node\">\n          {}\n        </Attribute>\n",
                item(format!("{name}/{step}"), dims, "Float")
            ));
        }
        x.push_str("      </Grid>\n");
    }
    x.push_str("    </Grid>\n  </Domain>\n</Xdmf>\n");
    x
}

/// The XDMF 3 text describing [`write_mode_datasets`]' datasets in the HDF5 file named
/// `h5`: one grid on the configuration linearized at, one vector attribute per mode.
pub fn modes_xdmf_text(h5: &str, layout: &ModesLayout) -> String {
    let (n, s) = (layout.n_points, layout.n_segments);
    let h5 = escape(h5);
    let item = |path: &str, dims: String, kind: &str| {
        format!("<DataItem Dimensions=\"{dims}\" NumberType=\"{kind}\" Precision=\"{}\" Format=\"HDF\">{h5}:/{GROUP}/{path}</DataItem>", if kind == "Int" { 4 } else { 8 })
    };
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n");
    x.push_str(&format!("    {XDMF_COMMENT_MARK}\n"));
    x.push_str("    <Grid Name=\"modes\" GridType=\"Uniform\">\n");
    x.push_str(&format!(
        "      <Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"{s}\">\n        {}\n      </Topology>\n",
        item("lines", format!("{s} 2"), "Int")
    ));
    x.push_str(&format!(
        "      <Geometry GeometryType=\"XYZ\">\n        {}\n      </Geometry>\n",
        item("points", format!("{n} 3"), "Float")
    ));
    for (k, &f) in layout.frequencies.iter().enumerate() {
        x.push_str(&format!(
            "      <Attribute Name=\"{}\" AttributeType=\"Vector\" Center=\"Node\">\n        {}\n      </Attribute>\n",
            escape(&mode_name(k, f)),
            item(&format!("shapes/{}", step_name(k)), format!("{n} 3"), "Float")
        ));
    }
    x.push_str("    </Grid>\n  </Domain>\n</Xdmf>\n");
    x
}

/// `&`, `<`, `>` and `"` as XML writes them in text and attributes.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Writes the XDMF file beside the result file `result` (atomically), naming the result
/// file by its file name (both in one folder).
pub fn write_xdmf(result: &Path, layout: &Layout) -> Result<PathBuf> {
    let x = xdmf_path(result);
    let name = result.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    super::atomic::write_bytes_atomically(&x, xdmf_text(&name, layout).as_bytes())?;
    Ok(x)
}

/// Writes the XDMF file of a modes file beside it (atomically), as [`write_xdmf`].
pub fn write_modes_xdmf(modes: &Path, layout: &ModesLayout) -> Result<PathBuf> {
    let x = xdmf_path(modes);
    let name = modes.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    super::atomic::write_bytes_atomically(&x, modes_xdmf_text(&name, layout).as_bytes())?;
    Ok(x)
}

/// [`write_datasets`] for a result file's `extra` stage, its errors naming `out`.
pub fn extra(f: &hdf5::File, out: &Path, bodies: &[BeamBody], r: &crate::simulate::SimulationResult) -> Result<Layout> {
    write_datasets(f, bodies, &r.t.to_vec(), &r.q, &r.qd).map_err(|e| Error::hdf5(out, e))
}
