//! Small wrappers over the `hdf5` crate: atomic file creation and typed attributes.

use crate::error::{Error, Result};
use hdf5::types::VarLenUnicode;
use hdf5_sys::h5t::{H5Tcopy, H5Tset_size, H5T_VARIABLE};
use std::path::Path;

/// Creates `path` atomically and durably: `fill` writes into a temporary file beside it
/// (unique name, created exclusively by flexrom, registered for removal on SIGINT/SIGTERM), which is
/// closed, `fdatasync`ed and renamed over `path` only when `fill` succeeds, then the folder is
/// `fsync`ed ([`super::atomic`]). A failed run never leaves a half-written file nor destroys a
/// previous good one; a missing folder is created.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&hdf5::File) -> Result<()>) -> Result<()> {
    let staged = StagedFile::create(path)?;
    fill(staged.file()).map_err(shorten)?;
    staged.commit()
}

/// An HDF5 file written atomically in stages, [`write_atomically`] cut in two:
/// [`StagedFile::create`] makes the temporary file beside `path`, [`StagedFile::commit`]
/// closes it and moves it into place (`fdatasync`, rename, folder `fsync`). Dropped
/// without a commit, the temporary file is closed and removed. Between the two the file
/// may move to another thread (a result file's fixed part is written beside the run,
/// [`super::result_file::begin_alongside`]).
pub struct StagedFile {
    // declared first, dropped first: the file is closed before its temporary is removed
    file: hdf5::File,
    tmp: super::atomic::TempPath,
    path: std::path::PathBuf,
}

impl StagedFile {
    pub fn create(path: &Path) -> Result<StagedFile> {
        let tmp = super::atomic::TempPath::file_for(path)?;
        // the empty temporary file is flexrom's own (created exclusively): truncated here
        let file =
            crate::io::h5_open::create(tmp.path()).map_err(|e| Error::hdf5(path, format!("cannot create: {e}")))?;
        Ok(StagedFile { file, tmp, path: path.to_path_buf() })
    }

    pub fn file(&self) -> &hdf5::File {
        &self.file
    }

    /// The final path (as given to [`Self::create`]).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes and closes the file, then `fdatasync`s it and renames it over the final path.
    pub fn commit(self) -> Result<()> {
        // on an error the whole struct is dropped: the file closed before its temporary goes
        self.file.flush().map_err(|e| shorten(Error::hdf5(&self.path, e)))?;
        let StagedFile { file, tmp, path: _ } = self;
        // closed before the fdatasync and the rename (the last handle closes the file)
        drop(file);
        tmp.commit()
    }
}

/// An HDF5 error's message cut to the system's one line ("cannot write: No space left on
/// device (errno 28)"); other errors as they are.
pub fn shorten(e: Error) -> Error {
    match e {
        Error::Hdf5 { file, problem } => Error::Hdf5 { file, problem: short_write_error(&problem) },
        other => other,
    }
}

/// HDF5's write errors span lines (time, temporary file name, buffer address, …); the
/// system's message is what the user can act on: "cannot write: No space left on device
/// (errno 28)".
fn short_write_error(problem: &str) -> String {
    let field = |key: &str| {
        problem
            .split(key)
            .nth(1)
            .and_then(|r| r.split(['\'', ',']).find(|s| !s.trim().is_empty()))
            .map(|s| s.trim().to_string())
    };
    match (field("error message = '"), field("errno = ")) {
        (Some(msg), Some(errno)) => format!("cannot write: {msg} (errno {errno})"),
        (Some(msg), None) => format!("cannot write: {msg}"),
        _ => problem.split_whitespace().collect::<Vec<_>>().join(" "),
    }
}

/// Writes the text attribute `name` = `value` on `loc`: a scalar, variable-length,
/// NUL-terminated UTF-8 string with a UTF-8 name, as
/// `loc.new_attr::<VarLenUnicode>().create(name)?.write_scalar(..)` writes it, in a dozen
/// HDF5 calls instead of the crate's ~40 (type built, looked up and compared twice, shapes
/// checked, handles validated on drop): the attributes were a sixth of writing a result
/// file (docs/process-speed.md). The same bytes reach the file (a test reads both back).
pub fn attr_str(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    use hdf5_sys::h5t::{H5T_cset_t, H5T_str_t, H5Tclose, H5Tset_cset, H5Tset_strpad};
    // the checks of `VarLenUnicode`'s parser: no NUL inside (HDF5 would cut the text there)
    let v: VarLenUnicode = value.parse().map_err(|e| hdf5::Error::from(format!("{e:?}")))?;
    let cname = attr_name(name)?;
    hdf5::sync::sync(|| {
        // SAFETY: plain calls into HDF5 under hdf5-metno's library lock (`sync`); the type
        // created here is checked and closed here. `H5Awrite` reads one `char*` from the
        // pointer, the one held by `v`, a NUL-terminated string that outlives the call,
        // which HDF5 only reads and copies.
        unsafe {
            let t = hdf5::h5check(H5Tcopy(*hdf5::globals::H5T_C_S1))?;
            let r = (|| -> hdf5::Result<()> {
                hdf5::h5check(H5Tset_cset(t, H5T_cset_t::H5T_CSET_UTF8))?;
                hdf5::h5check(H5Tset_strpad(t, H5T_str_t::H5T_STR_NULLTERM))?;
                hdf5::h5check(H5Tset_size(t, H5T_VARIABLE))?;
                let ptr: *const VarLenUnicode = &v;
                scalar_attr(loc, &cname, t, ptr.cast())
            })();
            H5Tclose(t);
            r
        }
    })
}

/// Writes the scalar `f64` attribute `name` = `value` on `loc`, as the crate's
/// `new_attr::<f64>().create(name)?.write_scalar(..)` does (the same type, a UTF-8 name; a
/// test compares), in a few raw calls ([`attr_str`] says why).
pub fn attr_f64(loc: &hdf5::Location, name: &str, value: f64) -> hdf5::Result<()> {
    let cname = attr_name(name)?;
    // SAFETY: under the library lock; `value` outlives the call and is one native double,
    // the type given
    hdf5::sync::sync(|| unsafe {
        scalar_attr(loc, &cname, *hdf5::globals::H5T_NATIVE_DOUBLE, (&value as *const f64).cast())
    })
}

/// [`attr_f64`] for a `u64`.
pub fn attr_u64(loc: &hdf5::Location, name: &str, value: u64) -> hdf5::Result<()> {
    let cname = attr_name(name)?;
    // SAFETY: as in attr_f64, one native unsigned 64-bit integer
    hdf5::sync::sync(|| unsafe {
        scalar_attr(loc, &cname, *hdf5::globals::H5T_NATIVE_UINT64, (&value as *const u64).cast())
    })
}

fn attr_name(name: &str) -> hdf5::Result<std::ffi::CString> {
    std::ffi::CString::new(name).map_err(|e| hdf5::Error::from(format!("attribute name `{name}`: {e}")))
}

/// Creates the scalar attribute `name` of type `t` on `loc` (UTF-8 name) and writes the
/// value at `value`.
///
/// # Safety
/// Call under the library lock (`hdf5::sync::sync`); `t` must be a valid datatype id and
/// `value` point at one value of that type (memory layout), alive for the call. Every id
/// created here is checked and closed here, on every path.
unsafe fn scalar_attr(
    loc: &hdf5::Location,
    name: &std::ffi::CStr,
    t: hdf5_sys::h5i::hid_t,
    value: *const std::ffi::c_void,
) -> hdf5::Result<()> {
    use hdf5_sys::h5::herr_t;
    use hdf5_sys::h5a::{H5Aclose, H5Acreate2, H5Awrite};
    use hdf5_sys::h5i::hid_t;
    use hdf5_sys::h5p::{H5Pclose, H5Pcreate, H5Pset_char_encoding, H5P_DEFAULT};
    use hdf5_sys::h5s::{H5S_class_t, H5Sclose, H5Screate};
    use hdf5_sys::h5t::H5T_cset_t;
    let mut ids: Vec<(hid_t, unsafe extern "C" fn(hid_t) -> herr_t)> = Vec::with_capacity(3);
    // SAFETY: the caller's contract; each id is pushed as soon as it exists, closed below
    let r = unsafe {
        (|| -> hdf5::Result<()> {
            let space = hdf5::h5check(H5Screate(H5S_class_t::H5S_SCALAR))?;
            ids.push((space, H5Sclose));
            let acpl = hdf5::h5check(H5Pcreate(*hdf5::globals::H5P_ATTRIBUTE_CREATE))?;
            ids.push((acpl, H5Pclose));
            hdf5::h5check(H5Pset_char_encoding(acpl, H5T_cset_t::H5T_CSET_UTF8))?;
            let a = hdf5::h5check(H5Acreate2(loc.id(), name.as_ptr(), t, space, acpl, H5P_DEFAULT))?;
            ids.push((a, H5Aclose));
            hdf5::h5check(H5Awrite(a, t, value))?;
            Ok(())
        })()
    };
    for (id, close) in ids.into_iter().rev() {
        // SAFETY: ids created above, closed once
        unsafe { close(id) };
    }
    r
}

/// Reads the text attribute `name` of `loc`. In a file read from disk, the attribute's heap
/// references are checked first ([`check_heap_references`]) against the file's global heap
/// collections ([`heaps_checked`]): libhdf5 follows a reference as it is, and a damaged one
/// crashed the process. Files open for writing are flexrom's own and take the fast path.
pub fn read_attr_str(loc: &hdf5::Location, name: &str) -> hdf5::Result<String> {
    let attr = loc.attr(name)?;
    if let Some(heaps) = heaps_checked(loc)? {
        check_heap_references(&attr, &format!("attribute `{name}`"), &heaps).map_err(as_hdf5)?;
    }
    Ok(attr.read_scalar::<VarLenUnicode>()?.as_str().to_string())
}

/// A check's finding as the hdf5 crate's error of the read it stops: its problem alone, as
/// the caller names the file.
fn as_hdf5(e: Error) -> hdf5::Error {
    hdf5::Error::from(e.problem())
}

/// Reads the one-dimensional dataset of variable-length strings `ds` (a sweep's
/// `/message`), its heap references checked first as [`read_attr_str`] checks an
/// attribute's: libhdf5 would follow a damaged one as it is.
pub fn read_strings(ds: &hdf5::Dataset) -> hdf5::Result<Vec<String>> {
    if let Some(heaps) = heaps_checked(ds)? {
        check_heap_references(ds, &format!("dataset `{}`", ds.name()), &heaps).map_err(as_hdf5)?;
    }
    Ok(ds.read_1d::<VarLenUnicode>()?.iter().map(|m| m.as_str().to_string()).collect())
}

/// The objects of a file's global heap collections, as [`check_global_heaps`] found them:
/// (collection address, object index) → object size in bytes.
pub type HeapObjects = std::collections::HashMap<(u64, u32), u64>;

/// The tag of the opaque memory type [`check_heap_references`] reads a text attribute as.
const RAW_VLEN_TAG: &std::ffi::CStr = c"flexrom raw variable-length reference";

/// Size in bytes of a variable-length value as stored in an attribute (file format,
/// "Variable-length data"): a 4-byte length, then the heap reference, an 8-byte collection
/// address and a 4-byte object index; the only layout [`check_heap_references`] accepts.
const RAW_VLEN_SIZE: usize = 16;

/// A conversion from a variable-length string as stored in the file to the opaque type
/// tagged [`RAW_VLEN_TAG`] that leaves the bytes as they are, so that the stored heap
/// references can be read without libhdf5 following them (its own conversion reads each
/// referenced object with `H5HG_read`, trusting address, index and length). Registered as
/// a soft conversion, it is offered every variable-length to opaque path and accepts only
/// that one: source of [`RAW_VLEN_SIZE`] bytes (the file's layout; in memory a text is a
/// pointer), destination of the same size with the tag.
extern "C" fn keep_raw_vlen(
    src: hdf5_sys::h5i::hid_t,
    dst: hdf5_sys::h5i::hid_t,
    cdata: *mut hdf5_sys::h5t::H5T_cdata_t,
    _n: usize,
    _buf_stride: usize,
    _bkg_stride: usize,
    _buf: *mut std::ffi::c_void,
    _bkg: *mut std::ffi::c_void,
    _dxpl: hdf5_sys::h5i::hid_t,
) -> hdf5_sys::h5::herr_t {
    use hdf5_sys::h5t::{H5T_bkg_t, H5T_cmd_t, H5Tget_size, H5Tget_tag, H5Tis_variable_str};
    // SAFETY: libhdf5 calls this with a valid `cdata` and type ids for the call; the tag is
    // a string libhdf5 allocates, compared and freed here
    unsafe {
        match (*cdata).command {
            H5T_cmd_t::H5T_CONV_INIT => {
                if H5Tis_variable_str(src) <= 0
                    || H5Tget_size(src) != RAW_VLEN_SIZE
                    || H5Tget_size(dst) != RAW_VLEN_SIZE
                {
                    return -1;
                }
                let tag = H5Tget_tag(dst);
                if tag.is_null() {
                    return -1;
                }
                let ours = std::ffi::CStr::from_ptr(tag) == RAW_VLEN_TAG;
                hdf5_sys::h5::H5free_memory(tag.cast());
                if !ours {
                    return -1;
                }
                (*cdata).need_bkg = H5T_bkg_t::H5T_BKG_NO;
                0
            }
            // same size, bytes kept: nothing to do
            H5T_cmd_t::H5T_CONV_CONV | H5T_cmd_t::H5T_CONV_FREE => 0,
        }
    }
}

/// Refuses the text attribute or dataset `attr` (`what` in messages) if a heap reference stored in it does not name an
/// object of `heaps` (the file's global heap collections, checked) whose size is the
/// stored length: libhdf5 1.10 follows a reference as it is, and a damaged collection
/// address or object index crashed the process (`H5HG_read`), a length shorter than the
/// object overran the buffer sized by it. The stored bytes are read through a conversion
/// that keeps them as they are (`keep_raw_vlen`), with no heap dereference. An attribute
/// that is not a variable-length string is left to the typed read that follows.
/// An [`Error::Hdf5`] naming the file.
pub fn check_heap_references(attr: &hdf5::Container, what: &str, heaps: &HeapObjects) -> Result<()> {
    let file = attr.filename();
    let bad = |problem: String| Error::hdf5(&file, problem);
    use hdf5_sys::h5a::{H5Aget_type, H5Aread};
    use hdf5_sys::h5d::{H5Dget_type, H5Dread};
    use hdf5_sys::h5i::{H5I_type_t, H5Iget_type};
    use hdf5_sys::h5p::H5P_DEFAULT;
    use hdf5_sys::h5s::H5S_ALL;
    use hdf5_sys::h5t::{H5T_class_t, H5T_pers_t, H5Tclose, H5Tcreate, H5Tis_variable_str, H5Tregister, H5Tset_tag};
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    // an attribute's or a dataset's texts (`read_attr_str`, `read_strings`): the same
    // stored layout, read by the matching call
    // SAFETY: `attr` holds a live id
    let is_attr = unsafe { H5Iget_type(attr.id()) } == H5I_type_t::H5I_ATTR;
    let n = attr.size();
    let raw = hdf5::sync::sync(|| -> Result<Option<Vec<u8>>> {
        // SAFETY: plain calls under the library lock; every type created here is closed
        // here; `H5Aread` writes `n` values of the 16-byte opaque type into a buffer of
        // that size (the conversion keeps the size)
        unsafe {
            let ft = if is_attr { H5Aget_type(attr.id()) } else { H5Dget_type(attr.id()) };
            if ft < 0 {
                return Err(bad(format!("{what}: its type cannot be read")));
            }
            let vlen_str = H5Tis_variable_str(ft) > 0;
            H5Tclose(ft);
            if !vlen_str {
                return Ok(None);
            }
            let t = H5Tcreate(H5T_class_t::H5T_OPAQUE, RAW_VLEN_SIZE);
            if t < 0 {
                return Err(bad("cannot create a memory type".into()));
            }
            let r = (|| {
                if H5Tset_tag(t, RAW_VLEN_TAG.as_ptr()) < 0 {
                    return Err(bad("cannot tag a memory type".to_string()));
                }
                let registered = *REGISTERED.get_or_init(|| {
                    let src = H5Tcopy(*hdf5::globals::H5T_C_S1);
                    let ok = src >= 0
                        && H5Tset_size(src, H5T_VARIABLE) >= 0
                        && H5Tregister(
                            H5T_pers_t::H5T_PERS_SOFT,
                            c"flexrom_keep_raw_vlen".as_ptr(),
                            src,
                            t,
                            Some(keep_raw_vlen),
                        ) >= 0;
                    if src >= 0 {
                        H5Tclose(src);
                    }
                    ok
                });
                if !registered {
                    return Err(bad("cannot register the raw reading of texts".to_string()));
                }
                let mut buf = vec![0u8; n * RAW_VLEN_SIZE];
                let read = if is_attr {
                    H5Aread(attr.id(), t, buf.as_mut_ptr().cast())
                } else {
                    H5Dread(attr.id(), t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.as_mut_ptr().cast())
                };
                if read < 0 {
                    return Err(bad(format!("{what}: its stored text references cannot be read")));
                }
                Ok(Some(buf))
            })();
            H5Tclose(t);
            r
        }
    })?;
    let Some(raw) = raw else { return Ok(()) };
    for v in raw.chunks_exact(RAW_VLEN_SIZE) {
        let len = u32::from_le_bytes(v[0..4].try_into().expect("4 bytes")) as u64;
        let collection = u64::from_le_bytes(v[4..12].try_into().expect("8 bytes"));
        let index = u32::from_le_bytes(v[12..16].try_into().expect("4 bytes"));
        if collection == 0 {
            // the nil reference (a null string, file format "Variable-length data"):
            // libhdf5 tests the address alone and reads no heap for it
            continue;
        }
        match heaps.get(&(collection, index)) {
            Some(&size) if size == len => {}
            Some(&size) => {
                return Err(bad(format!(
                    "{what} claims a text of {len} bytes where its heap object holds {size}: a damaged file"
                )))
            }
            None => {
                return Err(bad(format!(
                    "{what} refers to object {index} of a global heap at address {collection}, which the file does not hold: a damaged file"
                )))
            }
        }
    }
    Ok(())
}

/// [`check_global_heaps`] for the file of `loc`, once per file as it is on disk (path, size,
/// modification time), before its first text is read: the heap objects found, or `None` for
/// a file open for writing, flexrom's own, in the making, not read from disk.
pub fn heaps_checked(loc: &hdf5::Location) -> hdf5::Result<Option<std::sync::Arc<HeapObjects>>> {
    type Checked = Vec<((String, u64, std::time::SystemTime), std::sync::Arc<HeapObjects>)>;
    static CHECKED: std::sync::Mutex<Checked> = std::sync::Mutex::new(Vec::new());
    if !loc.file()?.is_read_only() {
        return Ok(None);
    }
    let name = loc.filename();
    let m = std::fs::metadata(&name).map_err(|e| hdf5::Error::from(format!("cannot be read: {e}")))?;
    let key = (name.clone(), m.len(), m.modified().unwrap_or(std::time::UNIX_EPOCH));
    if let Some((_, h)) = CHECKED.lock().unwrap_or_else(|e| e.into_inner()).iter().find(|(k, _)| *k == key) {
        return Ok(Some(h.clone()));
    }
    let heaps = std::sync::Arc::new(check_global_heaps(Path::new(&name)).map_err(as_hdf5)?);
    CHECKED.lock().unwrap_or_else(|e| e.into_inner()).push((key, heaps.clone()));
    Ok(Some(heaps))
}

pub fn read_attr_f64(loc: &hdf5::Location, name: &str) -> hdf5::Result<f64> {
    loc.attr(name)?.read_scalar::<f64>()
}

/// Opens dataset `name` of `loc` with its shape checked before anything is read: a crafted
/// or damaged shape must neither size an allocation nor leave an index out of bounds later.
/// An [`Error::Hdf5`] whose [`Error::problem`] is for a message after the file and the
/// dataset.
pub fn dataset_of_shape(loc: &hdf5::Group, name: &str, want: &[usize]) -> Result<hdf5::Dataset> {
    let d = loc.dataset(name).map_err(|e| Error::hdf5(loc.filename(), format!("cannot be read: {e}")))?;
    let shape = d.shape();
    if shape != want {
        let problem = format!("has shape {} where {} is expected", show_shape(&shape), show_shape(want));
        return Err(Error::hdf5(loc.filename(), problem));
    }
    Ok(d)
}

/// The length of the one-dimensional dataset `name` of `loc`, refused before anything is
/// read when what reading it brings along, `bytes_per_entry` for each entry, would exceed
/// the memory bound: the file alone sizes it, so a flipped bit must not size an allocation.
/// An [`Error::Hdf5`] or [`Error::Resource`] whose [`Error::problem_text`] is for a message after
/// the file and the dataset.
pub fn bounded_len(
    loc: &hdf5::Group,
    name: &str,
    bytes_per_entry: f64,
    limits: &crate::limits::Limits,
) -> Result<usize> {
    let d = loc.dataset(name).map_err(|e| Error::hdf5(loc.filename(), format!("cannot be read: {e}")))?;
    let shape = d.shape();
    let &[n] = shape.as_slice() else {
        return Err(Error::hdf5(loc.filename(), format!("has shape {}, expected one dimension", show_shape(&shape))));
    };
    limits.check_memory(&format!("its {n} entries"), n as f64 * bytes_per_entry)?;
    Ok(n)
}

/// Every dataset below `g` (groups followed; the caller has refused links other than hard
/// ones): its path from `g`, its shape and the bytes reading it takes.
pub fn datasets_below(g: &hdf5::Group) -> hdf5::Result<Vec<(String, Vec<usize>, f64)>> {
    let mut out = Vec::new();
    walk(g, "", &mut out)?;
    Ok(out)
}

fn walk(g: &hdf5::Group, prefix: &str, out: &mut Vec<(String, Vec<usize>, f64)>) -> hdf5::Result<()> {
    for name in g.member_names()? {
        let path = if prefix.is_empty() { name.clone() } else { format!("{prefix}/{name}") };
        if let Ok(sub) = g.group(&name) {
            walk(&sub, &path, out)?;
        } else if let Ok(d) = g.dataset(&name) {
            let shape = d.shape();
            // a variable-length string reads as a pointer and a length at least
            let each = d.dtype().map_or(16, |t| t.size().max(8)) as f64;
            let bytes = shape.iter().fold(each, |b, &n| b * n as f64);
            out.push((path, shape, bytes));
        }
    }
    Ok(())
}

fn show_shape(s: &[usize]) -> String {
    format!("({})", s.iter().map(usize::to_string).collect::<Vec<_>>().join(", "))
}

/// Refuses a file whose global heap collections (where HDF5 keeps variable-length strings:
/// every text attribute, a sweep's `/message`) do not hold together: an object whose size
/// runs past its collection, or a collection past the end of the file. libhdf5 1.10 trusts
/// those sizes, and reading a text from a damaged collection crashed the process
/// (`memcpy` in `H5HG_read`) or never returned; checked here, before any text is read.
///
/// A collection is found by its signature, `GCOL`, version 1 and three zero bytes (file
/// format, "Global Heap"); its size and each object's are 8-byte lengths, as in every file
/// flexrom and h5py write. A collection's address is its byte offset less the base address,
/// taken as where the superblock's signature is (0, or 512, 1024, … after a user block).
/// The objects found, for [`check_heap_references`]; an [`Error::Hdf5`] naming the file.
pub fn check_global_heaps(path: &Path) -> Result<HeapObjects> {
    let bad = |problem: String| Error::hdf5(path, problem);
    let b = std::fs::read(path).map_err(|e| bad(format!("cannot be read: {e}")))?;
    let base = std::iter::once(0)
        .chain((9..63).map(|k| 1usize << k))
        .take_while(|&o| o + 8 <= b.len())
        .find(|&o| &b[o..o + 8] == b"\x89HDF\r\n\x1a\n")
        .unwrap_or(0);
    let mut objects = HeapObjects::new();
    let u64_at = |i: usize| u64::from_le_bytes(b[i..i + 8].try_into().expect("8 bytes"));
    let signature = memchr::memmem::Finder::new(b"GCOL\x01\0\0\0");
    let mut from = 0;
    while let Some(k) = signature.find(&b[from..]) {
        let at = from + k;
        from = at + 8;
        if at + 16 > b.len() {
            return Err(bad(format!("global heap at byte {at} is cut off by the end of the file: a damaged file")));
        }
        let size = u64_at(at + 8);
        let end = (at as u64).checked_add(size).filter(|&e| e <= b.len() as u64 && size >= 16);
        let Some(end) = end.map(|e| e as usize) else {
            return Err(bad(format!(
                "global heap at byte {at} claims {size} bytes, past the end of the file: a damaged file"
            )));
        };
        // libhdf5's walk (`H5HG__cache_heap_deserialize`), step for step: a tail too short
        // for an object header is free space; index 0 is free space of its stated size,
        // header included, and the walk goes on after it
        let mut p = at + 16;
        while p + 16 <= end {
            let (index, object) = (u16::from_le_bytes([b[p], b[p + 1]]), u64_at(p + 8));
            let need = if index == 0 { object } else { object.saturating_add(16 + 7) / 8 * 8 };
            if need > (end - p) as u64 {
                return Err(bad(format!(
                    "global heap at byte {at}: object {index} claims {object} bytes, past the end of its collection: a damaged file"
                )));
            }
            if need == 0 {
                // libhdf5 would step by 0 bytes: it never returned
                return Err(bad(format!("global heap at byte {at}: its free space claims 0 bytes: a damaged file")));
            }
            if index != 0 && at >= base {
                objects.insert(((at - base) as u64, u32::from(index)), object);
            }
            p += need as usize;
        }
    }
    Ok(objects)
}

#[cfg(test)]
mod tests {
    /// `attr_str` writes what the crate's own attribute writer writes: read back equal
    /// (empty, multi-byte and long texts), of the same datatype (variable-length UTF-8,
    /// NUL-terminated) and with a UTF-8 name; a text with a NUL inside is refused.
    #[test]
    fn text_attributes_match_the_crate_writer() {
        use hdf5::types::VarLenUnicode;
        let d = tempfile::tempdir().unwrap();
        let f = hdf5::File::create(d.path().join("a.h5")).unwrap();
        let long = "ε".repeat(3000);
        for (i, text) in ["", "N·m (slope rows)", long.as_str()].iter().enumerate() {
            let mine = format!("mine {i} é");
            super::attr_str(&f, &mine, text).unwrap();
            let theirs = format!("theirs {i} é");
            f.new_attr::<VarLenUnicode>()
                .create(theirs.as_str())
                .unwrap()
                .write_scalar(&text.parse::<VarLenUnicode>().unwrap())
                .unwrap();
            assert_eq!(super::read_attr_str(&f, &mine).unwrap(), *text);
            let (a, b) = (f.attr(&mine).unwrap(), f.attr(&theirs).unwrap());
            assert_eq!(a.dtype().unwrap(), b.dtype().unwrap());
            assert_eq!(a.dtype().unwrap().to_descriptor().unwrap(), b.dtype().unwrap().to_descriptor().unwrap());
            assert_eq!(a.shape(), b.shape());
            assert_eq!(a.acpl().unwrap().char_encoding(), b.acpl().unwrap().char_encoding());
        }
        assert!(super::attr_str(&f, "nul", "a\0b").is_err());
        assert!(super::attr_str(&f, "nul\0name", "a").is_err());
        assert!(f.attr_names().unwrap().iter().all(|n| !n.starts_with("nul")));
        // read back from disk, through the check of heap references: both writers' texts pass
        drop(f);
        let f = hdf5::File::open(d.path().join("a.h5")).unwrap();
        for (i, text) in ["", "N·m (slope rows)", long.as_str()].iter().enumerate() {
            for who in ["mine", "theirs"] {
                assert_eq!(super::read_attr_str(&f, &format!("{who} {i} é")).unwrap(), *text, "{who} {i}");
            }
        }
    }

    /// `attr_f64` and `attr_u64` write what the crate's own builder writes: the same value,
    /// datatype, shape and name encoding.
    #[test]
    fn numeric_attributes_match_the_crate_writer() {
        let d = tempfile::tempdir().unwrap();
        let f = hdf5::File::create(d.path().join("a.h5")).unwrap();
        super::attr_f64(&f, "mine f é", -1.25e-7).unwrap();
        f.new_attr::<f64>().create("theirs f é").unwrap().write_scalar(&-1.25e-7).unwrap();
        super::attr_u64(&f, "mine u é", u64::MAX - 3).unwrap();
        f.new_attr::<u64>().create("theirs u é").unwrap().write_scalar(&(u64::MAX - 3)).unwrap();
        assert_eq!(f.attr("mine f é").unwrap().read_scalar::<f64>().unwrap(), -1.25e-7);
        assert_eq!(f.attr("mine u é").unwrap().read_scalar::<u64>().unwrap(), u64::MAX - 3);
        for k in ["f", "u"] {
            let (a, b) = (f.attr(&format!("mine {k} é")).unwrap(), f.attr(&format!("theirs {k} é")).unwrap());
            assert_eq!(a.dtype().unwrap(), b.dtype().unwrap(), "{k}");
            assert_eq!(a.dtype().unwrap().to_descriptor().unwrap(), b.dtype().unwrap().to_descriptor().unwrap());
            assert_eq!(a.shape(), b.shape());
            assert_eq!(a.acpl().unwrap().char_encoding(), b.acpl().unwrap().char_encoding());
        }
        assert!(super::attr_f64(&f, "nul\0name", 1.0).is_err());
    }

    #[test]
    fn hdf5_write_errors_are_one_line_with_the_system_message() {
        let p = "H5Dwrite(): can't write data: file write failed: time = Wed Nov 25 02:33:25 2026\n, filename = '/tmp/x/.out.h5.flexrom-tmp-1-0', file descriptor = 5, errno = 28, error message = 'No space left on device', buf = 0x55, total write size = 32424";
        assert_eq!(super::short_write_error(p), "cannot write: No space left on device (errno 28)");
        assert_eq!(super::short_write_error("a\n b"), "a b");
    }
}
