//! Results as a table with named columns, printed as aligned text, CSV (RFC 4180, one
//! header line) or JSON (an array with one object per row, keys in column order). A
//! missing value (`None`, or a NaN) is an empty CSV cell and a JSON `null`; numbers are
//! written in Rust's shortest round-trip form, so reading them back gives the same `f64`.

use crate::error::{Error, Result};

/// How a command prints its results (`--csv`, `--json`, else text).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Format {
    #[default]
    Text,
    Csv,
    Json,
}

impl Format {
    /// From the `--csv` and `--json` flags (clap keeps them exclusive).
    pub fn from_flags(csv: bool, json: bool) -> Format {
        match (csv, json) {
            (true, _) => Format::Csv,
            (_, true) => Format::Json,
            _ => Format::Text,
        }
    }
}

/// One cell: a number, an integer, a text, a flag or nothing.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    Num(f64),
    Int(i64),
    Text(String),
    Bool(bool),
    Null,
}

impl From<f64> for Cell {
    fn from(x: f64) -> Self {
        if x.is_nan() {
            Cell::Null
        } else {
            Cell::Num(x)
        }
    }
}
impl From<Option<f64>> for Cell {
    fn from(x: Option<f64>) -> Self {
        x.map_or(Cell::Null, Cell::from)
    }
}
impl From<usize> for Cell {
    fn from(x: usize) -> Self {
        Cell::Int(x as i64)
    }
}
impl From<u64> for Cell {
    fn from(x: u64) -> Self {
        Cell::Int(x as i64)
    }
}
impl From<bool> for Cell {
    fn from(x: bool) -> Self {
        Cell::Bool(x)
    }
}
impl From<&str> for Cell {
    fn from(x: &str) -> Self {
        Cell::Text(x.to_string())
    }
}
impl From<String> for Cell {
    fn from(x: String) -> Self {
        Cell::Text(x)
    }
}

impl Cell {
    fn text(&self) -> String {
        match self {
            // ±∞ (a failed estimate) is written as `inf`/`-inf`, which CSV readers parse
            // both forms are Rust's shortest round trip; the exponent form where the plain
            // one would spell out many zeros
            Cell::Num(x) if *x != 0.0 && x.is_finite() && !(1e-4..1e15).contains(&x.abs()) => format!("{x:e}"),
            Cell::Num(x) => format!("{x}"),
            Cell::Int(i) => i.to_string(),
            Cell::Text(s) => s.clone(),
            Cell::Bool(b) => b.to_string(),
            Cell::Null => String::new(),
        }
    }

    fn json(&self) -> serde_json::Value {
        match self {
            // JSON has no ∞: written as null like NaN
            Cell::Num(x) => serde_json::Number::from_f64(*x).map_or(serde_json::Value::Null, serde_json::Value::Number),
            Cell::Int(i) => (*i).into(),
            Cell::Text(s) => s.clone().into(),
            Cell::Bool(b) => (*b).into(),
            Cell::Null => serde_json::Value::Null,
        }
    }
}

/// Named columns and rows of cells (every row as long as `columns`).
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    pub fn new(columns: &[&str]) -> Table {
        Table { columns: columns.iter().map(|c| c.to_string()).collect(), rows: Vec::new() }
    }

    /// Appends a row; a row of the wrong length is a bug of the caller.
    pub fn push(&mut self, row: Vec<Cell>) {
        assert_eq!(row.len(), self.columns.len(), "table row length");
        self.rows.push(row);
    }

    /// A one-row table from the fields of a serialisable record (e.g. `validate`'s
    /// result): arrays become one column per element, `name_1`, `name_2`, … (1-based, as
    /// "fifth 1 … 5" reads), nested objects `outer.inner`.
    pub fn from_record(record: &impl serde::Serialize) -> Result<Table> {
        let err = |e: serde_json::Error| Error::usage(format!("cannot write the record: {e}"));
        // through the text, read back field by field: a `serde_json::Map` would sort the keys
        let text = serde_json::to_string(record).map_err(err)?;
        Table::from_json_records(&format!("[{text}]"))
    }

    /// A table from a JSON array of objects (e.g. a report's `validation.json`), one row
    /// each, flattened as [`Table::from_record`]; the columns are the first object's keys
    /// in their written order, and a key another object lacks is an empty cell.
    pub fn from_json_records(text: &str) -> Result<Table> {
        let records: Vec<Ordered> = serde_json::from_str(text)
            .map_err(|e| Error::usage(format!("cannot read the records as a JSON array of objects: {e}")))?;
        let mut t = Table::default();
        for (i, rec) in records.iter().enumerate() {
            let (mut cols, mut row) = (Vec::new(), Vec::new());
            for (k, v) in &rec.0 {
                flatten(k, v, &mut cols, &mut row);
            }
            if i == 0 {
                t.columns = cols;
                t.rows.push(row);
            } else {
                let cell = |c: &String| cols.iter().position(|x| x == c).map_or(Cell::Null, |j| row[j].clone());
                let aligned = t.columns.iter().map(cell).collect();
                t.rows.push(aligned);
            }
        }
        Ok(t)
    }

    /// CSV: a header line and one line per row.
    pub fn to_csv(&self) -> Result<String> {
        let err = |e: csv::Error| Error::usage(format!("cannot write the CSV: {e}"));
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(&self.columns).map_err(err)?;
        for r in &self.rows {
            w.write_record(r.iter().map(Cell::text)).map_err(err)?;
        }
        let bytes = w.into_inner().map_err(|e| Error::usage(format!("cannot write the CSV: {e}")))?;
        String::from_utf8(bytes).map_err(|e| Error::usage(format!("cannot write the CSV: {e}")))
    }

    /// JSON: an array of objects, one per row, keys in column order.
    pub fn to_json(&self) -> String {
        let rows: Vec<String> = self.rows.iter().map(|r| self.row_json(r)).collect();
        format!("[{}]", rows.join(","))
    }

    /// The first row as one JSON object (for commands whose result is a single record);
    /// an empty table is an empty object.
    pub fn to_json_object(&self) -> String {
        self.rows.first().map_or_else(|| "{}".to_string(), |r| self.row_json(r))
    }

    fn row_json(&self, r: &[Cell]) -> String {
        let fields: Vec<String> = self
            .columns
            .iter()
            .zip(r)
            .map(|(k, c)| format!("{}:{}", serde_json::Value::from(k.as_str()), c.json()))
            .collect();
        format!("{{{}}}", fields.join(","))
    }

    /// Aligned text columns (right-aligned, two spaces apart), a header line first.
    pub fn to_text(&self) -> String {
        let cells: Vec<Vec<String>> = std::iter::once(self.columns.clone())
            .chain(
                self.rows
                    .iter()
                    .map(|r| r.iter().map(|c| if *c == Cell::Null { "-".into() } else { c.text() }).collect()),
            )
            .collect();
        let widths: Vec<usize> =
            (0..self.columns.len()).map(|j| cells.iter().map(|r| r[j].chars().count()).max().unwrap_or(0)).collect();
        let mut out = String::new();
        for r in &cells {
            let line: Vec<String> = r.iter().zip(&widths).map(|(c, w)| format!("{c:>w$}")).collect();
            out.push_str(line.join("  ").trim_end());
            out.push('\n');
        }
        out
    }
}

/// A JSON object's fields in the order they were written.
struct Ordered(Vec<(String, serde_json::Value)>);

impl<'de> serde::Deserialize<'de> for Ordered {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Ordered;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a JSON object")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> std::result::Result<Ordered, A::Error> {
                let mut out = Vec::new();
                while let Some(kv) = m.next_entry()? {
                    out.push(kv);
                }
                Ok(Ordered(out))
            }
        }
        d.deserialize_map(V)
    }
}

fn flatten(prefix: &str, v: &serde_json::Value, columns: &mut Vec<String>, row: &mut Vec<Cell>) {
    use serde_json::Value;
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let name = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                flatten(&name, x, columns, row);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                flatten(&format!("{prefix}_{}", i + 1), x, columns, row);
            }
        }
        _ => {
            columns.push(prefix.to_string());
            row.push(match v {
                Value::Null => Cell::Null,
                Value::Bool(b) => Cell::Bool(*b),
                Value::Number(n) => n.as_i64().map_or_else(|| Cell::from(n.as_f64().unwrap_or(f64::NAN)), Cell::Int),
                Value::String(s) => Cell::Text(s.clone()),
                _ => unreachable!("arrays and objects are handled above"),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Table {
        let mut t = Table::new(&["load_scale", "name", "error", "ok"]);
        t.push(vec![0.1.into(), "tip, end".into(), f64::NAN.into(), true.into()]);
        t.push(vec![1.0e-7.into(), "a \"quoted\" name".into(), Some(2.5e-4).into(), false.into()]);
        t
    }

    /// CSV read back with the csv crate: same header, quoted commas and quotes intact,
    /// numbers bit-for-bit, NaN as an empty cell.
    #[test]
    fn csv_reads_back() {
        let text = sample().to_csv().unwrap();
        let mut r = csv::Reader::from_reader(text.as_bytes());
        assert_eq!(r.headers().unwrap().iter().collect::<Vec<_>>(), ["load_scale", "name", "error", "ok"]);
        let rows: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0][1], *"tip, end");
        assert_eq!(rows[0][2], *"");
        assert_eq!(rows[1][0].parse::<f64>().unwrap(), 1.0e-7);
        assert_eq!(&rows[1][0], "1e-7", "small numbers in exponent form");
        assert_eq!(&rows[0][0], "0.1");
        assert_eq!(rows[1][1], *"a \"quoted\" name");
        assert_eq!(rows[1][2].parse::<f64>().unwrap(), 2.5e-4);
    }

    /// JSON parsed with serde_json: an array of objects whose keys keep column order and
    /// whose NaN is null.
    #[test]
    fn json_reads_back() {
        let t = sample();
        let v: serde_json::Value = serde_json::from_str(&t.to_json()).unwrap();
        let a = v.as_array().unwrap();
        assert_eq!(a.len(), 2);
        assert!(a[0]["error"].is_null());
        assert_eq!(a[1]["error"].as_f64(), Some(2.5e-4));
        assert_eq!(a[0]["name"], "tip, end");
        assert_eq!(a[0]["ok"], true);
        let text = t.to_json();
        assert!(text.find("load_scale").unwrap() < text.find("\"ok\"").unwrap(), "column order kept");
        let one: serde_json::Value = serde_json::from_str(&t.to_json_object()).unwrap();
        assert_eq!(one["load_scale"].as_f64(), Some(0.1));
    }

    /// Records read back from JSON keep the written key order, not the sorted one; a key
    /// missing from a later record is an empty cell.
    #[test]
    fn json_records_keep_order() {
        let t = Table::from_json_records(r#"[{"z": 1, "a": [2.5, null]}, {"a": [1, 2]}]"#).unwrap();
        assert_eq!(t.columns, ["z", "a_1", "a_2"]);
        assert_eq!(t.rows[1], vec![Cell::Null, Cell::Int(1), Cell::Int(2)]);
        assert!(Table::from_json_records("{}").is_err());
    }

    /// A record's arrays become numbered columns, 1-based.
    #[test]
    fn record_flattens_arrays() {
        #[derive(serde::Serialize)]
        struct R {
            x: f64,
            by: Vec<f64>,
            range: Option<[f64; 2]>,
        }
        let t = Table::from_record(&R { x: 1.5, by: vec![1.0, 2.0], range: None }).unwrap();
        assert_eq!(t.columns, ["x", "by_1", "by_2", "range"]);
        assert_eq!(t.rows[0], vec![Cell::Num(1.5), Cell::Num(1.0), Cell::Num(2.0), Cell::Null]);
    }
}
