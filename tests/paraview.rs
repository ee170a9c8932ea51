//! `--paraview`: the XDMF file beside a result is well-formed XML whose every `DataItem`
//! names a dataset of the result file with the shape it states; the points are the
//! centre line (the tip probe at ξ = 1 is the last sample, to round-off: both are S(1) e,
//! the tip node), the pinned end does not move (velocity 0 at the pin), and without the
//! option nothing is added.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexrom")).args(args).env("HDF5_USE_FILE_LOCKING", "FALSE").output().unwrap()
}

fn ok(args: &[&str]) -> Output {
    let o = flexrom(args);
    assert!(o.status.success(), "flexrom {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    o
}

fn model(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/models").join(name).display().to_string()
}

/// The tags of `xml`, checked to nest (every open tag closed in order, `<?...?>` and
/// `<.../>` and `<!-- -->` standing alone); returns (name, attributes text, text after it) per tag.
fn well_formed(xml: &str) -> Vec<(String, String, String)> {
    let mut stack: Vec<String> = Vec::new();
    let mut tags = Vec::new();
    let mut rest = xml;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("every < closed by >") + start;
        let tag = &rest[start + 1..end];
        let after = &rest[end + 1..];
        let text = after[..after.find('<').unwrap_or(after.len())].trim().to_string();
        if tag.starts_with('?') {
            assert!(tag.ends_with('?'));
        } else if tag.starts_with("!--") {
            assert!(tag.ends_with("--"), "comment <{tag}>");
        } else if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name), "closing tag </{name}> out of order");
        } else {
            let name: String = tag.chars().take_while(|c| !c.is_whitespace() && *c != '/').collect();
            let attrs = tag[name.len()..].trim_end_matches('/').to_string();
            assert_eq!(attrs.matches('"').count() % 2, 0, "quotes of <{tag}>");
            if !tag.ends_with('/') {
                stack.push(name.clone());
            }
            tags.push((name, attrs, text));
        }
        rest = &rest[end + 1..];
    }
    assert!(stack.is_empty(), "unclosed: {stack:?}");
    tags
}

fn attr(attrs: &str, name: &str) -> String {
    let key = format!("{name}=\"");
    let s = &attrs[attrs.find(&key).unwrap_or_else(|| panic!("{name} in {attrs}")) + key.len()..];
    s[..s.find('"').unwrap()].to_string()
}

#[test]
fn the_xdmf_names_the_datasets_it_describes() {
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("p.h5");
    // the pendulum (50 elements, one body) over 4 steps of 0.005 s: 5 instants, 201 points
    ok(&["simulate", &model("pendulum.toml"), "-o", h5.to_str().unwrap(), "--t-end", "0.02", "--paraview", "-q"]);
    let xml = std::fs::read_to_string(dir.path().join("p.xdmf")).unwrap();
    let tags = well_formed(&xml);
    assert_eq!(tags.iter().filter(|t| t.0 == "Time").count(), 5);
    let f = flexrom::io::h5_open::open(&h5).unwrap();
    let mut items = 0;
    for (_, attrs, text) in tags.iter().filter(|t| t.0 == "DataItem") {
        let (file, path) = text.split_once(':').unwrap();
        assert_eq!(file, "p.h5");
        let dims: Vec<usize> = attr(attrs, "Dimensions").split(' ').map(|d| d.parse().unwrap()).collect();
        assert_eq!(f.dataset(path).unwrap_or_else(|_| panic!("{path}")).shape(), dims, "{path}");
        items += 1;
    }
    // per instant: lines, points, strain, curvature, velocity
    assert_eq!(items, 5 * 5);
    let n = 4 * 50 + 1;
    assert_eq!(f.dataset("paraview/lines").unwrap().shape(), [n - 1, 2]);
    let tip = f.dataset("probes/tip").unwrap().read_2d::<f64>().unwrap();
    for k in 0..5 {
        let p = f.dataset(&format!("paraview/points/{k:06}")).unwrap().read_2d::<f64>().unwrap();
        let v = f.dataset(&format!("paraview/velocity/{k:06}")).unwrap().read_2d::<f64>().unwrap();
        assert!((p[[n - 1, 0]] - tip[[k, 0]]).abs() < 1e-14 && (p[[n - 1, 1]] - tip[[k, 1]]).abs() < 1e-14);
        assert!(v.row(0).iter().all(|x| x.abs() < 1e-12), "the pinned end does not move");
        assert!(p.column(2).iter().all(|&z| z == 0.0));
    }
    // the units table labels every dataset
    let d = f.dataset("paraview/curvature/000004").unwrap();
    assert_eq!(d.attr("units").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap().as_str(), "1/m");
    // without --paraview: no group, no XDMF file; an XDMF file flexrom did not write is kept
    let plain = dir.path().join("q.h5");
    ok(&["simulate", &model("pendulum.toml"), "-o", plain.to_str().unwrap(), "--t-end", "0.01", "-q"]);
    assert!(flexrom::io::h5_open::open(&plain).unwrap().group("paraview").is_err());
    assert!(!Path::new(&dir.path().join("q.xdmf")).exists());
    std::fs::write(dir.path().join("q.xdmf"), "mine").unwrap();
    let o = flexrom(&["simulate", &model("pendulum.toml"), "-o", plain.to_str().unwrap(), "--paraview", "-q"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && err.contains("q.xdmf") && err.contains("--paraview"), "{err}");
    assert_eq!(std::fs::read_to_string(dir.path().join("q.xdmf")).unwrap(), "mine");
}

/// `modes --paraview`: one grid on the configuration linearized at, one vector attribute
/// per mode named by its number and the frequency of `/frequencies`, every `DataItem` a
/// dataset of the modes file with the stated shape; the field of mode k is S(ξ) φ_k, so
/// at the tip sample (ξ = 1 of the last element, S(1) picks the last node's x, y) it is
/// that node's entries of row k of `/shapes`, and at the pin it is 0 (B φ = 0).
#[test]
fn the_modes_xdmf_names_one_field_per_mode() {
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("m.h5");
    ok(&["modes", &model("pendulum.toml"), "--count", "3", "-o", h5.to_str().unwrap(), "--paraview", "-q"]);
    let xml = std::fs::read_to_string(dir.path().join("m.xdmf")).unwrap();
    let tags = well_formed(&xml);
    let f = flexrom::io::h5_open::open(&h5).unwrap();
    let freq = f.dataset("frequencies").unwrap().read_1d::<f64>().unwrap();
    let names: Vec<String> = tags.iter().filter(|t| t.0 == "Attribute").map(|t| attr(&t.1, "Name")).collect();
    let expected: Vec<String> = (0..3).map(|k| format!("mode_{} ({:.6} Hz)", k + 1, freq[k])).collect();
    assert_eq!(names, expected);
    assert_eq!(tags.iter().filter(|t| t.0 == "Grid").count(), 1);
    let mut items = 0;
    for (_, attrs, text) in tags.iter().filter(|t| t.0 == "DataItem") {
        let (file, path) = text.split_once(':').unwrap();
        assert_eq!(file, "m.h5");
        let dims: Vec<usize> = attr(attrs, "Dimensions").split(' ').map(|d| d.parse().unwrap()).collect();
        assert_eq!(f.dataset(path).unwrap_or_else(|_| panic!("{path}")).shape(), dims, "{path}");
        items += 1;
    }
    // lines, points and 3 shapes
    assert_eq!(items, 5);
    // 50 elements: 4 samples an element and the last node; 51 nodes of 4 coordinates
    let (n, n_dof) = (4 * 50 + 1, 4 * 51);
    let shapes = f.dataset("shapes").unwrap().read_2d::<f64>().unwrap();
    let q = f.dataset("q").unwrap().read_1d::<f64>().unwrap();
    let p = f.dataset("paraview/points").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(p.shape(), [n, 3]);
    assert!((p[[n - 1, 0]] - q[n_dof - 4]).abs() < 1e-14 && (p[[n - 1, 1]] - q[n_dof - 3]).abs() < 1e-14);
    for k in 0..3 {
        let u = f.dataset(&format!("paraview/shapes/{k:06}")).unwrap().read_2d::<f64>().unwrap();
        let scale = shapes.row(k).iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!((u[[n - 1, 0]] - shapes[[k, n_dof - 4]]).abs() <= 1e-12 * scale, "mode {k} tip x");
        assert!((u[[n - 1, 1]] - shapes[[k, n_dof - 3]]).abs() <= 1e-12 * scale, "mode {k} tip y");
        assert!(u.row(0).iter().all(|x| x.abs() <= 1e-12 * scale), "mode {k}: the pin does not move");
        assert!(u.column(2).iter().all(|&z| z == 0.0));
    }
    let d = f.dataset("paraview/shapes/000002").unwrap();
    assert_eq!(d.attr("units").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap().as_str(), "m/√kg");
    // without --paraview: no group, no XDMF file
    let plain = dir.path().join("n.h5");
    ok(&["modes", &model("pendulum.toml"), "--count", "2", "-o", plain.to_str().unwrap(), "-q"]);
    assert!(flexrom::io::h5_open::open(&plain).unwrap().group("paraview").is_err());
    assert!(!dir.path().join("n.xdmf").exists());
    // flexrom's own modes XDMF file is replaced, another kept
    ok(&["modes", &model("pendulum.toml"), "--count", "2", "-o", h5.to_str().unwrap(), "--paraview", "-q"]);
    assert_eq!(
        well_formed(&std::fs::read_to_string(dir.path().join("m.xdmf")).unwrap()).len(),
        tags.len() - 2,
        "one mode fewer: an Attribute and its DataItem"
    );
    std::fs::write(dir.path().join("n.xdmf"), "mine").unwrap();
    let o = flexrom(&["modes", &model("pendulum.toml"), "-o", plain.to_str().unwrap(), "--paraview", "-q"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && err.contains("n.xdmf") && err.contains("--paraview"), "{err}");
}
