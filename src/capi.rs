//! The C interface of `include/voxelkit.h`: opaque handles, status codes with a per-thread
//! message, and no panic across the boundary.
//!
//! Every export runs its body under `catch_unwind`. Handles are registered in a table of live
//! objects and looked up (with their kind) before any dereference, so NULL, freed and
//! mistyped handles and double frees are errors, not undefined behaviour. Every computation
//! is a `pipeline::Job`, like the CLI's: cancellation (the flag, or a progress callback that
//! returns non-zero) is the observer's answer, the workers skip what is left and the call
//! returns `VK_ERROR_CANCELLED`. No algorithm and no orchestration lives here.

use crate::choice::Choice;
use crate::error::{Error, Result};
use crate::grid::{Channels, Coord, LEAF_VOXELS, Leaf, SparseGrid, Transform};
use crate::implicit::Coordinates;
use crate::io::grid_export::ExportedGrid;
use crate::io::vdb::{Compression, MetaValue, WriteOptions, meta_entries, read_vdb_solid};
use crate::mesh::{GridFit, Mesh};
use crate::ops::csg::BooleanOp;
use crate::pipeline::request::{
    CombineRequest, Directions, FillKind, FloodKind, ImplicitRequest, LimitsRequest, LinesRequest,
    MeasureRequest, MeshRequest, Placement, Request, Schema, SolidRequest, SubdivRequest,
    SurfaceKind, ToMeshRequest, WriteRequest,
};
use crate::pipeline::to_mesh::check_mesh_output;
use crate::pipeline::{Details, GridSource, Job, MeasureSource, MeshSource, Outcome, Task};
use crate::progress::Observer;
use crate::solids::depth_layers::Layers;
use crate::voxelize::Separability;
use crate::voxelize::separating::Criterion;
use glam::DVec3;
use serde_json::Value;
use std::any::Any;
use std::cell::RefCell;
use std::collections::HashMap;
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::ops::ControlFlow;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, LazyLock, Mutex};

/// `vk_status`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VkStatus {
    Ok = 0,
    InvalidArgument = 1,
    InvalidHandle = 2,
    Io = 3,
    Parse = 4,
    BadMesh = 5,
    TooLarge = 6,
    Vdb = 7,
    Cancelled = 8,
    BufferTooSmall = 9,
    Internal = 10,
}

/// `vk_measures`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VkMeasures {
    pub inside_voxels: u64,
    pub surface_voxels: u64,
    pub volume_inside: f64,
    pub volume_with_surface: f64,
}

/// `vk_progress_fn`.
pub type VkProgressFn = extern "C" fn(done: u64, total: u64, user_data: *mut c_void) -> c_int;

/// `vk_mesh`.
pub struct VkMesh(Mesh);
/// `vk_grid`: a grid and the `.vdb` metadata of the job that made it.
pub struct VkGrid {
    /// Every grid of the job that made it (a level set's interior, a solid's shell ...),
    /// its metadata and report: what the CLI would write.
    outcome: Outcome,
    /// The metadata every written grid carries, as C strings that live as long as the grid.
    metadata: Vec<(CString, MetaValue, CString)>,
}

impl From<Outcome> for VkGrid {
    fn from(outcome: Outcome) -> Self {
        let given: Vec<(&str, MetaValue)> = outcome
            .metadata
            .iter()
            .map(|(k, v)| (k.as_str(), v.clone()))
            .collect();
        let c = |s: String| CString::new(s.replace('\0', "")).unwrap_or_default();
        let metadata = meta_entries(&given)
            .into_iter()
            .map(|(k, v)| {
                let text = c(v.to_string());
                (c(k), v, text)
            })
            .collect();
        VkGrid { outcome, metadata }
    }
}
/// `vk_options`: changed by the setters, copied by each call.
pub struct VkOptions(Mutex<Options>);

// SAFETY: the raw pointers in `Options` are the caller's progress user data and cancel flag,
// which the header lets calls on any thread use (the flag is read atomically).
unsafe impl Send for Options {}

/// What the setters set: the requests of `pipeline::request` (their defaults are the
/// options' defaults) and the grid they share.
#[derive(Clone)]
struct Options {
    /// The grid every call shares, and its fit.
    placement: Placement,
    fit: GridFit,
    mesh: MeshRequest,
    solid: SolidRequest,
    subdivision: SubdivRequest,
    lines: LinesRequest,
    limits: LimitsRequest,
    write: WriteRequest,
    to_mesh: ToMeshRequest,
    progress: Option<(VkProgressFn, *mut c_void)>,
    cancel: *const AtomicI32,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            placement: Placement::default(),
            fit: GridFit::from_options(None, None),
            mesh: MeshRequest::default(),
            solid: SolidRequest::default(),
            subdivision: SubdivRequest::default(),
            lines: LinesRequest::default(),
            limits: LimitsRequest::default(),
            write: WriteRequest::default(),
            to_mesh: ToMeshRequest::default(),
            progress: None,
            cancel: std::ptr::null(),
        }
    }
}

/// A failed call: its status and message.
struct Failure {
    status: VkStatus,
    message: String,
}

impl Failure {
    fn new(status: VkStatus, message: impl Into<String>) -> Self {
        Failure {
            status,
            message: message.into(),
        }
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        let status = match &e {
            Error::Io { .. } => VkStatus::Io,
            Error::Parse { .. } | Error::Formula { .. } | Error::UnsupportedFormat { .. } => {
                VkStatus::Parse
            }
            Error::BadFace { .. } | Error::EmptyMesh { .. } | Error::BadMesh(_) => {
                VkStatus::BadMesh
            }
            Error::TooLarge { .. } => VkStatus::TooLarge,
            Error::Vdb { .. } => VkStatus::Vdb,
            Error::Cancelled => VkStatus::Cancelled,
            _ => VkStatus::InvalidArgument,
        };
        Failure::new(status, e.to_string())
    }
}

type Status = std::result::Result<(), Failure>;

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs an export's body: no panic escapes, the message is kept, the status returned.
fn guard(body: impl FnOnce() -> Status) -> VkStatus {
    quiet_panics_during_calls();
    ACTIVE_CALLS.fetch_add(1, Ordering::SeqCst);
    IN_CALL.with(|c| c.set(true));
    let caught = catch_unwind(AssertUnwindSafe(body));
    IN_CALL.with(|c| c.set(false));
    ACTIVE_CALLS.fetch_sub(1, Ordering::SeqCst);
    let outcome = caught.unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Failure::new(
            VkStatus::Internal,
            format!("internal error (a bug in voxelkit, please report it): {what}"),
        ))
    });
    match outcome {
        Ok(()) => {
            set_last_error("");
            VkStatus::Ok
        }
        Err(f) => {
            set_last_error(&f.message);
            f.status
        }
    }
}

thread_local! {
    static IN_CALL: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}
/// Calls into the library in progress, on any thread.
static ACTIVE_CALLS: AtomicUsize = AtomicUsize::new(0);

/// A panic inside a call becomes its status and message (`vk_last_error`); it is not also
/// printed on the host's stderr. Panics of the host's own Rust code still print.
fn quiet_panics_during_calls() {
    static INSTALLED: std::sync::Once = std::sync::Once::new();
    INSTALLED.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let ours = IN_CALL.with(|c| c.get())
                || (ACTIVE_CALLS.load(Ordering::SeqCst) > 0
                    && rayon::current_thread_index().is_some());
            if !ours {
                previous(info);
            }
        }));
    });
}

/// What kind of object a live handle points to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Mesh,
    Grid,
    Options,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Mesh => "vk_mesh",
            Kind::Grid => "vk_grid",
            Kind::Options => "vk_options",
        }
    }
}

/// A live object: its kind and the object, shared with the calls using it right now.
struct Entry {
    kind: Kind,
    object: Arc<dyn Any + Send + Sync>,
}

/// Every handle given out and not yet freed. A handle is a number, never an address, and
/// never given out twice: a freed or forged handle finds nothing, even after new objects
/// were made, and an object freed while another thread still uses it lives until that use
/// ends.
static LIVE: LazyLock<Mutex<HashMap<usize, Entry>>> = LazyLock::new(Default::default);
static NEXT_HANDLE: AtomicUsize = AtomicUsize::new(1);

fn live() -> std::sync::MutexGuard<'static, HashMap<usize, Entry>> {
    // A panic never happens while the table is locked, but do not let one poison it.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Registers `value` and writes its new handle to `out`.
fn hand_out<T: Any + Send + Sync>(value: T, kind: Kind, out: *mut *mut T) -> Status {
    let out = non_null_out(out)?;
    // Spaced by 16 so that a handle looks like an aligned address to tools that print it.
    let id = NEXT_HANDLE.fetch_add(1, Ordering::Relaxed) << 4;
    let object: Arc<dyn Any + Send + Sync> = Arc::new(value);
    live().insert(id, Entry { kind, object });
    // SAFETY: `out` is non-null and, by the header's contract, points to writable storage.
    unsafe { *out = id as *mut T };
    Ok(())
}

fn not_live(kind: Kind, p: usize, found: Option<Kind>) -> Failure {
    Failure::new(
        VkStatus::InvalidHandle,
        match found {
            _ if p == 0 => format!("{} is NULL", kind.name()),
            Some(k) => format!(
                "a {} was passed where a {} is expected",
                k.name(),
                kind.name()
            ),
            None => format!(
                "{} {p:#x} is not a live handle (freed already, or never created)",
                kind.name()
            ),
        },
    )
}

/// The object behind a live handle of `kind`.
fn borrow<T: Any + Send + Sync>(p: *const T, kind: Kind) -> std::result::Result<Arc<T>, Failure> {
    let table = live();
    match table.get(&(p as usize)) {
        Some(e) if e.kind == kind => Ok(Arc::clone(&e.object)
            .downcast::<T>()
            .expect("the table holds each kind's own type")),
        found => Err(not_live(kind, p as usize, found.map(|e| e.kind))),
    }
}

/// Releases a handle of `kind`; NULL is fine, anything not live is an error. Removing it
/// from the table is the one step, so two threads freeing one handle cannot both succeed.
fn release<T>(p: *mut T, kind: Kind) -> Status {
    if p.is_null() {
        return Ok(());
    }
    let mut table = live();
    match table.get(&(p as usize)) {
        Some(e) if e.kind == kind => {
            table.remove(&(p as usize));
            Ok(())
        }
        found => Err(not_live(kind, p as usize, found.map(|e| e.kind))),
    }
}

/// The options behind a live handle, to change them.
fn options_mut(p: *mut VkOptions) -> std::result::Result<Arc<VkOptions>, Failure> {
    borrow(p as *const VkOptions, Kind::Options)
}

fn lock(options: &VkOptions) -> std::sync::MutexGuard<'_, Options> {
    options.0.lock().unwrap_or_else(|e| e.into_inner())
}

/// A copy of the options behind a live handle, for one call.
fn options_of(p: *const VkOptions) -> std::result::Result<Options, Failure> {
    let options: Arc<VkOptions> = borrow(p, Kind::Options)?;
    Ok(lock(&options).clone())
}

fn non_null_out<T>(out: *mut T) -> std::result::Result<*mut T, Failure> {
    if out.is_null() {
        Err(Failure::new(
            VkStatus::InvalidArgument,
            "an output pointer is NULL",
        ))
    } else {
        Ok(out)
    }
}

/// Writes `value` through a non-null output pointer.
fn put<T>(out: *mut T, value: T) -> Status {
    let out = non_null_out(out)?;
    // SAFETY: non-null and writable by the header's contract.
    unsafe { out.write(value) };
    Ok(())
}

fn c_str<'a>(p: *const c_char, what: &str) -> std::result::Result<&'a str, Failure> {
    if p.is_null() {
        return Err(Failure::new(
            VkStatus::InvalidArgument,
            format!("{what} is NULL"),
        ));
    }
    // SAFETY: non-null, and the caller passes a NUL-terminated string.
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .map_err(|_| Failure::new(VkStatus::InvalidArgument, format!("{what} is not UTF-8")))
}

/// A caller array of `len` elements; NULL only when empty.
fn slice<'a, T>(p: *const T, len: usize, what: &str) -> std::result::Result<&'a [T], Failure> {
    if len == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Failure::new(
            VkStatus::InvalidArgument,
            format!("{what} is NULL but {len} elements were announced"),
        ));
    }
    // No array in memory holds more than isize::MAX bytes: a larger count is a wrong one.
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(invalid(format!(
            "{what}: {len} elements cannot be an array in memory"
        )));
    }
    // SAFETY: non-null and, by the caller's contract, `len` readable elements (no more bytes
    // than an allocation can hold).
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

fn slice_mut<'a, T>(
    p: *mut T,
    len: usize,
    what: &str,
) -> std::result::Result<&'a mut [T], Failure> {
    if len == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(Failure::new(
            VkStatus::InvalidArgument,
            format!("{what} is NULL but room for {len} elements was announced"),
        ));
    }
    // SAFETY: non-null and, by the caller's contract, `len` writable elements.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, len) })
}

fn invalid(message: impl Into<String>) -> Failure {
    Failure::new(VkStatus::InvalidArgument, message)
}

/// Progress reporting and cancellation for one call: the caller's callback and cancel flag
/// as an observer, so that cancelling stops the workers without unwinding.
struct Reporter {
    total: AtomicU64,
    done: AtomicU64,
    callback: Option<(VkProgressFn, *mut c_void)>,
    cancel: *const AtomicI32,
    /// Held while the callback runs, so it is never called twice at once.
    calling: Mutex<()>,
    stop: AtomicBool,
}

// SAFETY: the raw pointers are the caller's: the user data goes back to the caller's own
// callback (never two calls at once), and the cancel flag is only read atomically, as the
// header requires of the caller's writes.
unsafe impl Sync for Reporter {}

impl Reporter {
    fn new(options: &Options) -> Self {
        Reporter {
            total: AtomicU64::new(0),
            done: AtomicU64::new(0),
            callback: options.progress,
            cancel: options.cancel,
            calling: Mutex::new(()),
            stop: AtomicBool::new(false),
        }
    }

    fn cancelled(&self) -> bool {
        // SAFETY: a non-null flag stays valid while calls with these options run.
        self.stop.load(Ordering::Relaxed)
            || (!self.cancel.is_null() && unsafe { &*self.cancel }.load(Ordering::Relaxed) != 0)
    }

    /// Tells the callback the work is done (item counts are estimates for some methods).
    fn finish(&self) {
        if let Some((callback, user)) = self.callback {
            let total = self.total.load(Ordering::Relaxed);
            let _one_at_a_time = self.calling.lock();
            callback(total, total, user);
        }
    }
}

impl Observer for Reporter {
    fn stage(&self, _name: &str, total: u64) {
        self.total.store(total, Ordering::Relaxed);
        self.done.store(0, Ordering::Relaxed);
    }

    fn advance(&self, n: u64) -> ControlFlow<()> {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let total = self.total.load(Ordering::Relaxed);
        if let Some((callback, user)) = self.callback
            && let Ok(_one_at_a_time) = self.calling.try_lock()
            && callback(done.min(total), total, user) != 0
        {
            self.stop.store(true, Ordering::Relaxed);
        }
        if self.cancelled() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Runs `task` as a job with the options' grid, threads, memory limit, progress and cancel
/// flag.
fn run_job(options: &Options, task: Task) -> std::result::Result<Outcome, Failure> {
    let reporter = Reporter::new(options);
    if reporter.cancelled() {
        return Err(Failure::new(
            VkStatus::Cancelled,
            "cancelled before it started",
        ));
    }
    let job = Job {
        task,
        fit: options.fit,
        limits: options.limits.limits(),
        up_axis: Default::default(),
    };
    let outcome = job.run(&reporter)?;
    reporter.finish();
    Ok(outcome)
}

/// The measures of a solid job's report.
fn solid_measures(outcome: &Outcome) -> std::result::Result<VkMeasures, Failure> {
    match &outcome.report.details {
        Details::Solid(s) => Ok(VkMeasures {
            inside_voxels: s.inside_voxels,
            surface_voxels: s.surface_voxels,
            volume_inside: s.volume_inside,
            volume_with_surface: s.volume_with_surface,
        }),
        _ => Err(Failure::new(
            VkStatus::Internal,
            "internal error (a bug in voxelkit, please report it): a solid without measures",
        )),
    }
}

/// The mesh of a handle, as a job's source.
fn mesh_source(mesh: *const VkMesh) -> std::result::Result<MeshSource, Failure> {
    Ok(MeshSource::Mesh(borrow(mesh, Kind::Mesh)?.0.clone()))
}

/// The common shape of an export that makes a grid: checked options and output, then the
/// job `task` makes.
fn grid_from_job(
    options: *const VkOptions,
    out: *mut *mut VkGrid,
    task: impl FnOnce(&Options) -> std::result::Result<Task, Failure>,
) -> VkStatus {
    guard(|| {
        let o = &options_of(options)?;
        non_null_out(out)?;
        let outcome = run_job(o, task(o)?)?;
        hand_out(VkGrid::from(outcome), Kind::Grid, out)
    })
}

/// The common shape of an export that fills a solid: `grid_from_job`'s, with the solid's
/// measures (by `measures_of`) put where `measures` points, when it is not null.
fn solid_from_job(
    options: *const VkOptions,
    out: *mut *mut VkGrid,
    measures: *mut VkMeasures,
    task: impl FnOnce(&Options) -> std::result::Result<Task, Failure>,
    measures_of: impl FnOnce(&Outcome) -> std::result::Result<VkMeasures, Failure>,
) -> VkStatus {
    guard(|| {
        let o = &options_of(options)?;
        non_null_out(out)?;
        let outcome = run_job(o, task(o)?)?;
        let found = measures_of(&outcome)?;
        if !measures.is_null() {
            put(measures, found)?;
        }
        hand_out(VkGrid::from(outcome), Kind::Grid, out)
    })
}

// ---- exports ---------------------------------------------------------------------------------

#[unsafe(no_mangle)]
pub extern "C" fn vk_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_debug_panic() -> VkStatus {
    guard(|| panic!("vk_debug_panic was called"))
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_mesh_load(path: *const c_char, out: *mut *mut VkMesh) -> VkStatus {
    guard(|| {
        non_null_out(out)?;
        let mesh = Mesh::load_lines(&PathBuf::from(c_str(path, "path")?))?;
        hand_out(VkMesh(mesh), Kind::Mesh, out)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_mesh_from_triangles(
    positions: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    out: *mut *mut VkMesh,
) -> VkStatus {
    guard(|| {
        non_null_out(out)?;
        let coords = vertex_count
            .checked_mul(3)
            .ok_or_else(|| invalid("vertex_count is too large"))?;
        let corners = triangle_count
            .checked_mul(3)
            .ok_or_else(|| invalid("triangle_count is too large"))?;
        let p = slice(positions, coords, "positions")?;
        let t = slice(triangles, corners, "triangles")?;
        // The copy: the points, one polygon per triangle, and the mesh's own vectors.
        let bytes = (vertex_count as u64)
            .saturating_mul(2 * 24)
            .saturating_add((triangle_count as u64).saturating_mul(2 * 12 + 24 + 8));
        crate::system::check_fits(
            bytes,
            None,
            &format!("a mesh of {vertex_count} vertices and {triangle_count} triangles"),
        )?;
        let points: Vec<DVec3> = p.chunks_exact(3).map(DVec3::from_slice).collect();
        let polygons: Vec<Vec<u32>> = t.chunks_exact(3).map(|c| c.to_vec()).collect();
        let mut mesh = Mesh::from_polygons("vk_mesh_from_triangles", points, &polygons);
        mesh.numbered_from_zero = true;
        mesh.validate()?;
        hand_out(VkMesh(mesh), Kind::Mesh, out)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_mesh_counts(
    mesh: *const VkMesh,
    vertices: *mut usize,
    faces: *mut usize,
) -> VkStatus {
    guard(|| {
        let m = &borrow(mesh, Kind::Mesh)?.0;
        non_null_out(vertices)?;
        non_null_out(faces)?;
        put(vertices, m.positions.len())?;
        put(faces, m.face_count())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_mesh_copy_triangles(
    mesh: *const VkMesh,
    positions: *mut f64,
    triangles: *mut u32,
) -> VkStatus {
    guard(|| {
        let m = &borrow(mesh, Kind::Mesh)?.0;
        if let Some(f) = (0..m.face_count()).find(|&f| m.face(f).len() != 3) {
            return Err(invalid(format!(
                "face {f} has {} corners: vk_mesh_copy_triangles copies triangle meshes",
                m.face(f).len()
            )));
        }
        let p = slice_mut(positions, 3 * m.positions.len(), "positions")?;
        for (out, v) in p.chunks_exact_mut(3).zip(&m.positions) {
            out.copy_from_slice(&v.to_array());
        }
        let t = slice_mut(triangles, 3 * m.face_count(), "triangles")?;
        t.copy_from_slice(&m.indices);
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_mesh_free(mesh: *mut VkMesh) -> VkStatus {
    guard(|| release(mesh, Kind::Mesh))
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_new(out: *mut *mut VkOptions) -> VkStatus {
    guard(|| {
        hand_out(
            VkOptions(Mutex::new(Options::default())),
            Kind::Options,
            out,
        )
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_free(options: *mut VkOptions) -> VkStatus {
    guard(|| release(options, Kind::Options))
}

/// Changes the options of a live handle.
fn set(
    options: *mut VkOptions,
    change: impl FnOnce(&mut Options) -> std::result::Result<(), Failure>,
) -> VkStatus {
    guard(|| {
        let options = options_mut(options)?;
        let mut o = lock(&options);
        change(&mut o)
    })
}

/// `request` with `changes` made as its JSON would have them: the check and error text of
/// Python's keywords.
fn changed<R: Schema>(request: &R, changes: Vec<(&str, Value)>) -> Result<R> {
    let mut values =
        serde_json::to_value(request).map_err(|e| Error::InvalidArgument(e.to_string()))?;
    for (field, value) in changes {
        values[field] = value;
    }
    R::from_json(values)
}

/// Sets `field` of a request on a mesh. A placement field (`resolution`, `voxel_size`,
/// `origin`, `bounds`) sets the grid every call shares instead: `resolution` and `voxel_size`
/// each replacing the other.
fn set_field<R: Request>(
    request: &mut R,
    placement: &mut Placement,
    fit: &mut GridFit,
    field: &str,
    value: Value,
) -> Result<()> {
    let new = changed(request, vec![(field, value.clone())])?;
    if !Placement::FIELDS.contains(&field) {
        *request = new;
        return Ok(());
    }
    let json = serde_json::to_value(&new).map_err(|e| Error::InvalidArgument(e.to_string()))?;
    let given: Placement =
        serde_json::from_value(json).map_err(|e| Error::InvalidArgument(e.to_string()))?;
    let place = match field {
        "resolution" => Placement {
            resolution: given.resolution,
            voxel_size: None,
            ..*placement
        },
        "voxel_size" => Placement {
            resolution: None,
            voxel_size: given.voxel_size,
            ..*placement
        },
        "origin" => Placement {
            origin: given.origin,
            ..*placement
        },
        _ => Placement {
            bounds: given.bounds,
            ..*placement
        },
    };
    *fit = place.fit()?;
    *placement = place;
    Ok(())
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set(
    options: *mut VkOptions,
    request: *const c_char,
    field: *const c_char,
    value: *const c_char,
) -> VkStatus {
    set(options, |o| {
        let request = c_str(request, "request")?;
        let field = c_str(field, "field")?;
        let text = c_str(value, "value")?;
        let value: Value = serde_json::from_str(text)
            .map_err(|e| invalid(format!("{field}: {text:?} is not a JSON value ({e})")))?;
        match request {
            "mesh" => set_field(&mut o.mesh, &mut o.placement, &mut o.fit, field, value)?,
            "solid" => set_field(&mut o.solid, &mut o.placement, &mut o.fit, field, value)?,
            "subdiv" => set_field(
                &mut o.subdivision,
                &mut o.placement,
                &mut o.fit,
                field,
                value,
            )?,
            "lines" => set_field(&mut o.lines, &mut o.placement, &mut o.fit, field, value)?,
            "limits" => o.limits = changed(&o.limits, vec![(field, value)])?,
            "write" => o.write = changed(&o.write, vec![(field, value)])?,
            "to_mesh" => {
                let request = changed(&o.to_mesh, vec![(field, value)])?;
                request.result_adaptivity()?;
                o.to_mesh = request;
            }
            other => {
                return Err(invalid(format!(
                    "no request {other:?} in the C options: mesh, solid, subdiv, lines, limits, \
                     write or to_mesh"
                )));
            }
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_compression(
    options: *mut VkOptions,
    compression: c_int,
) -> VkStatus {
    set(options, |o| {
        o.write.compression = Compression::from_code(i64::from(compression)).map_err(invalid)?;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_half(options: *mut VkOptions, half: c_int) -> VkStatus {
    set(options, |o| {
        o.write.half = half != 0;
        Ok(())
    })
}

/// The band of `vk_options_set_sdf` and `_udf`: on (true) for a positive half width, off for 0.
fn distance_band_option(band: f64) -> std::result::Result<bool, Failure> {
    if band == 0.0 {
        return Ok(false);
    }
    crate::pipeline::request::positive("band", band)?;
    Ok(true)
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_sdf(options: *mut VkOptions, band: f64) -> VkStatus {
    set(options, |o| {
        let on = distance_band_option(band)?;
        (o.mesh.sdf, o.solid.sdf) = (on, on);
        o.mesh.udf &= !on;
        if on {
            (o.mesh.band, o.solid.band) = (band, band);
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_udf(options: *mut VkOptions, band: f64) -> VkStatus {
    set(options, |o| {
        let on = distance_band_option(band)?;
        o.mesh.udf = on;
        o.mesh.sdf &= !on;
        if on {
            o.mesh.band = band;
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_resolution(options: *mut VkOptions, resolution: u32) -> VkStatus {
    set(options, |o| {
        let place = Placement {
            resolution: Some(resolution),
            voxel_size: None,
            ..o.placement
        };
        o.fit = place.fit()?;
        o.placement = place;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_voxel_size(options: *mut VkOptions, voxel_size: f64) -> VkStatus {
    set(options, |o| {
        let place = Placement {
            resolution: None,
            voxel_size: Some(voxel_size),
            ..o.placement
        };
        o.fit = place.fit()?;
        o.placement = place;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_separability(
    options: *mut VkOptions,
    separability: c_int,
) -> VkStatus {
    set(options, |o| {
        let separability = Separability::from_number(i64::from(separability)).map_err(invalid)?;
        o.mesh.separability = separability;
        o.subdivision.adjacency = separability.flood_adjacency();
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_criterion(options: *mut VkOptions, criterion: c_int) -> VkStatus {
    set(options, |o| {
        o.mesh.criterion = Criterion::from_code(i64::from(criterion)).map_err(invalid)?;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_normals(options: *mut VkOptions, normals: c_int) -> VkStatus {
    set(options, |o| {
        o.mesh.normals = normals != 0;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_surface_method(
    options: *mut VkOptions,
    method: c_int,
) -> VkStatus {
    set(options, |o| {
        o.mesh.method = SurfaceKind::from_code(i64::from(method)).map_err(invalid)?;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_fill_method(options: *mut VkOptions, method: c_int) -> VkStatus {
    set(options, |o| {
        o.solid.method = FillKind::from_code(i64::from(method)).map_err(invalid)?;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_flood(
    options: *mut VkOptions,
    flooding_xyz: c_int,
    graystack: usize,
) -> VkStatus {
    set(options, |o| {
        let xyz = flooding_xyz != 0;
        o.solid.flood = if xyz {
            FloodKind::Xyz
        } else {
            FloodKind::Blocks
        };
        o.solid.graystack = graystack;
        // The subdivision solid floods by FloodingXYZ (unless it takes depth layers): it takes
        // the stack when given.
        o.subdivision.graystack = if xyz {
            graystack
        } else {
            SubdivRequest::default().graystack
        };
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_depth_layers(
    options: *mut VkOptions,
    directions: u32,
    double_layers: c_int,
) -> VkStatus {
    set(options, |o| {
        let directions = Directions::Count(directions as usize);
        directions.set()?;
        o.solid.directions = directions;
        o.solid.layers = if double_layers != 0 {
            Layers::Double
        } else {
            Layers::Single
        };
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_subdivision(
    options: *mut VkOptions,
    presplit: u32,
    enclose: c_int,
) -> VkStatus {
    set(options, |o| {
        let changed = SubdivRequest {
            presplit,
            enclose: enclose != 0,
            ..o.subdivision.clone()
        };
        changed.options()?;
        o.subdivision = changed;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_threads(options: *mut VkOptions, threads: u32) -> VkStatus {
    set(options, |o| {
        o.limits.threads = Some(threads);
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_max_memory(options: *mut VkOptions, mib: u64) -> VkStatus {
    set(options, |o| {
        o.limits.max_memory_mib = Some(mib);
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_progress(
    options: *mut VkOptions,
    callback: Option<VkProgressFn>,
    user_data: *mut c_void,
) -> VkStatus {
    guard(|| {
        let options: Arc<VkOptions> = options_mut(options)?;
        lock(&options).progress = callback.map(|c| (c, user_data));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_options_set_cancel_flag(
    options: *mut VkOptions,
    flag: *const i32,
) -> VkStatus {
    guard(|| {
        // An `int32_t` written atomically by the caller has the layout of an `AtomicI32`.
        let options: Arc<VkOptions> = options_mut(options)?;
        lock(&options).cancel = flag.cast();
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_voxelize_mesh(
    mesh: *const VkMesh,
    options: *const VkOptions,
    out: *mut *mut VkGrid,
) -> VkStatus {
    grid_from_job(options, out, |o| Ok(o.mesh.task(mesh_source(mesh)?)?))
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_voxelize_lines(
    mesh: *const VkMesh,
    options: *const VkOptions,
    out: *mut *mut VkGrid,
) -> VkStatus {
    grid_from_job(options, out, |o| Ok(o.lines.task(mesh_source(mesh)?)?))
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_voxelize_subdivision(
    mesh: *const VkMesh,
    options: *const VkOptions,
    out: *mut *mut VkGrid,
) -> VkStatus {
    grid_from_job(options, out, |o| {
        Ok(o.subdivision.task(mesh_source(mesh)?)?)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_voxelize_formula(
    formula: *const c_char,
    coordinates: c_int,
    bounds_min: *const f64,
    bounds_max: *const f64,
    options: *const VkOptions,
    out: *mut *mut VkGrid,
) -> VkStatus {
    grid_from_job(options, out, |_| {
        let coords = Coordinates::from_code(i64::from(coordinates)).map_err(invalid)?;
        let min = DVec3::from_slice(slice(bounds_min, 3, "bounds_min")?);
        let max = DVec3::from_slice(slice(bounds_max, 3, "bounds_max")?);
        if !(min.is_finite() && max.is_finite()) {
            return Err(invalid(format!(
                "the bounds {min} .. {max} must be finite numbers"
            )));
        }
        let request = ImplicitRequest {
            coords,
            bounds: crate::pipeline::request::Bounds::Box([min.to_array(), max.to_array()]),
            ..ImplicitRequest::default()
        };
        Ok(request.task(c_str(formula, "formula")?.to_string())?)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_fill_mesh(
    mesh: *const VkMesh,
    options: *const VkOptions,
    solid: *mut *mut VkGrid,
    measures: *mut VkMeasures,
) -> VkStatus {
    let task = |o: &Options| Ok(o.solid.task(mesh_source(mesh)?)?);
    let measures_of = |outcome: &Outcome| match &outcome.report.details {
        Details::DepthLayers(d) if d.unclassified_voxels > 0 => Err(invalid(format!(
            "{} voxels cannot be classified by depth layers (crossed more than four times \
             along every direction, or on rays that cross an open mesh an odd number of times)",
            d.unclassified_voxels
        ))),
        Details::DepthLayers(d) => Ok(VkMeasures {
            inside_voxels: d.inside_voxels,
            surface_voxels: 0,
            volume_inside: d.volume,
            volume_with_surface: d.volume,
        }),
        // A level set: the centres inside it.
        Details::DistanceBand(_) => {
            let inside = outcome.solid_voxels().voxel_count();
            let volume = inside as f64 * outcome.grid.transform.voxel_size.powi(3);
            Ok(VkMeasures {
                inside_voxels: inside,
                surface_voxels: 0,
                volume_inside: volume,
                volume_with_surface: volume,
            })
        }
        _ => solid_measures(outcome),
    };
    solid_from_job(options, solid, measures, task, measures_of)
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_fill_subdivision(
    mesh: *const VkMesh,
    options: *const VkOptions,
    solid: *mut *mut VkGrid,
    measures: *mut VkMeasures,
) -> VkStatus {
    let task = |o: &Options| {
        let request = SubdivRequest {
            solid: true,
            ..o.subdivision.clone()
        };
        Ok(request.task(mesh_source(mesh)?)?)
    };
    solid_from_job(options, solid, measures, task, solid_measures)
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_measure_surface(
    surface: *const VkGrid,
    measures: *mut VkMeasures,
) -> VkStatus {
    guard(|| {
        let g = &borrow(surface, Kind::Grid)?.outcome.grid;
        non_null_out(measures)?;
        let task = MeasureRequest::default().task(MeasureSource::Grid(g.clone()))?;
        let outcome = run_job(&Options::default(), task)?;
        put(measures, solid_measures(&outcome)?)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_combine(
    a: *const VkGrid,
    b: *const VkGrid,
    op: c_int,
    resample: c_int,
    out: *mut *mut VkGrid,
) -> VkStatus {
    guard(|| {
        let (a, b) = (
            borrow(a, Kind::Grid)?.outcome.solid_voxels(),
            borrow(b, Kind::Grid)?.outcome.solid_voxels(),
        );
        non_null_out(out)?;
        let request = CombineRequest {
            op: BooleanOp::from_code(i64::from(op)).map_err(invalid)?,
            resample: resample != 0,
            ..CombineRequest::default()
        };
        let task = request.task((GridSource::Grid(a), GridSource::Grid(b)))?;
        let outcome = run_job(&Options::default(), task)?;
        hand_out(VkGrid::from(outcome), Kind::Grid, out)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_read_vdb(
    path: *const c_char,
    name: *const c_char,
    out: *mut *mut VkGrid,
) -> VkStatus {
    guard(|| {
        non_null_out(out)?;
        let name = if name.is_null() {
            None
        } else {
            Some(c_str(name, "name")?)
        };
        let path = PathBuf::from(c_str(path, "path")?);
        let grid = read_vdb_solid(&path, name)?;
        let mut outcome = Outcome::from_voxels(grid, &path.display().to_string());
        outcome.metadata = vec![("source_file".to_string(), path.display().to_string().into())];
        hand_out(VkGrid::from(outcome), Kind::Grid, out)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_write_vdb(grid: *const VkGrid, path: *const c_char) -> VkStatus {
    guard(|| {
        let g = borrow(grid, Kind::Grid)?;
        let path = PathBuf::from(c_str(path, "path")?);
        Ok(g.outcome
            .write_files(&path, &[], &write_options_of(std::ptr::null())?)?)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_write_vdb_with(
    grid: *const VkGrid,
    path: *const c_char,
    options: *const VkOptions,
) -> VkStatus {
    guard(|| {
        let g = borrow(grid, Kind::Grid)?;
        let path = PathBuf::from(c_str(path, "path")?);
        let write = options_of(options)?.write.options();
        Ok(g.outcome.write_files(&path, &[], &write)?)
    })
}

/// The adaptivity of `options` (NULL: the default).
fn adaptivity_of(options: *const VkOptions) -> std::result::Result<f64, Failure> {
    if options.is_null() {
        return Ok(ToMeshRequest::default().adaptivity);
    }
    Ok(options_of(options)?.to_mesh.adaptivity)
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_to_mesh(grid: *const VkGrid, out: *mut *mut VkMesh) -> VkStatus {
    vk_grid_to_mesh_with(grid, std::ptr::null(), out)
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_to_mesh_with(
    grid: *const VkGrid,
    options: *const VkOptions,
    out: *mut *mut VkMesh,
) -> VkStatus {
    guard(|| {
        non_null_out(out)?;
        let g = borrow(grid, Kind::Grid)?;
        let surface = g.outcome.surface_mesh(adaptivity_of(options)?)?;
        let polygons: Vec<Vec<u32>> = surface.triangles.iter().map(|t| t.to_vec()).collect();
        let mut mesh = Mesh::from_polygons("vk_grid_to_mesh", surface.positions, &polygons);
        mesh.numbered_from_zero = true;
        hand_out(VkMesh(mesh), Kind::Mesh, out)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_write_mesh(grid: *const VkGrid, path: *const c_char) -> VkStatus {
    vk_grid_write_mesh_with(grid, path, std::ptr::null())
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_write_mesh_with(
    grid: *const VkGrid,
    path: *const c_char,
    options: *const VkOptions,
) -> VkStatus {
    guard(|| {
        let path = PathBuf::from(c_str(path, "path")?);
        check_mesh_output(&path, &[])?;
        let adaptivity = adaptivity_of(options)?;
        Ok(borrow(grid, Kind::Grid)?
            .outcome
            .save_mesh(&path, adaptivity)?)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_voxel_count(grid: *const VkGrid, count: *mut u64) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        put(count, g.voxel_count())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_leaf_count(grid: *const VkGrid, count: *mut usize) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        put(count, g.leaf_count())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_transform(
    grid: *const VkGrid,
    voxel_size: *mut f64,
    origin: *mut f64,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        non_null_out(voxel_size)?;
        let o = slice_mut(origin, 3, "origin")?;
        o.copy_from_slice(&g.transform.origin.to_array());
        put(voxel_size, g.transform.voxel_size)
    })
}

/// Leaves `first .. first + count` of `grid`, or an error naming the valid range.
fn leaf_range(
    grid: &SparseGrid,
    first: usize,
    count: usize,
) -> std::result::Result<&[crate::grid::Leaf], Failure> {
    let n = grid.leaf_count();
    match first.checked_add(count) {
        Some(end) if end <= n => Ok(&grid.leaves()[first..end]),
        _ => Err(invalid(format!(
            "leaves {first} .. {first}+{count} are out of range: the grid has {n}"
        ))),
    }
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_copy_leaves(
    grid: *const VkGrid,
    first: usize,
    count: usize,
    origins: *mut i32,
    masks: *mut u64,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        let leaves = leaf_range(g, first, count)?;
        let origins = slice_mut(origins, 3 * count, "origins")?;
        let masks = slice_mut(masks, 8 * count, "masks")?;
        for (k, leaf) in leaves.iter().enumerate() {
            for a in 0..3 {
                origins[3 * k + a] = i32::try_from(leaf.origin[a])
                    .ok()
                    .filter(|v| v.checked_add(7).is_some())
                    .ok_or_else(|| {
                        invalid(format!(
                            "leaf {} at {:?} lies beyond 32-bit coordinates",
                            first + k,
                            leaf.origin
                        ))
                    })?;
            }
            masks[8 * k..8 * k + 8].copy_from_slice(&leaf.mask);
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_tile_count(grid: *const VkGrid, count: *mut usize) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        put(count, g.tiles().with_edges().count())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_copy_tiles(
    grid: *const VkGrid,
    first: usize,
    count: usize,
    origins: *mut i32,
    edges: *mut i32,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        let tiles: Vec<_> = g.tiles().with_edges().collect();
        let n = tiles.len();
        let chosen = match first.checked_add(count) {
            Some(end) if end <= n => &tiles[first..end],
            _ => {
                return Err(invalid(format!(
                    "tiles {first} .. {first}+{count} are out of range: the grid has {n}"
                )));
            }
        };
        let origins = slice_mut(origins, 3 * count, "origins")?;
        let edges = slice_mut(edges, count, "edges")?;
        for (k, &(origin, edge)) in chosen.iter().enumerate() {
            for a in 0..3 {
                origins[3 * k + a] = i32::try_from(origin[a])
                    .ok()
                    .filter(|v| v.checked_add(edge as i32).is_some())
                    .ok_or_else(|| {
                        invalid(format!("tile at {origin:?} lies beyond 32-bit coordinates"))
                    })?;
            }
            edges[k] = edge as i32;
        }
        Ok(())
    })
}

/// Copies a per-voxel `[f32; 3]` channel of leaves `first .. first + count`.
fn copy_channel(
    grid: *const VkGrid,
    first: usize,
    count: usize,
    out: *mut f32,
    name: &str,
    channel: fn(&crate::grid::Leaf) -> Option<&[[f32; 3]; LEAF_VOXELS]>,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        let leaves = leaf_range(g, first, count)?;
        let out = slice_mut(out, 3 * LEAF_VOXELS * count, name)?;
        for (k, leaf) in leaves.iter().enumerate() {
            let values =
                channel(leaf).ok_or_else(|| invalid(format!("the grid has no {name} channel")))?;
            let dst = &mut out[3 * LEAF_VOXELS * k..3 * LEAF_VOXELS * (k + 1)];
            dst.fill(0.0);
            for n in leaf.offsets() {
                dst[3 * n..3 * n + 3].copy_from_slice(&values[n]);
            }
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_copy_normals(
    grid: *const VkGrid,
    first: usize,
    count: usize,
    normals: *mut f32,
) -> VkStatus {
    copy_channel(grid, first, count, normals, "normals", |l| {
        l.normal.as_deref()
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_copy_colors(
    grid: *const VkGrid,
    first: usize,
    count: usize,
    colors: *mut f32,
) -> VkStatus {
    copy_channel(grid, first, count, colors, "colors", |l| l.color.as_deref())
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_copy_voxels(
    grid: *const VkGrid,
    coords: *mut i64,
    capacity: usize,
    written: *mut usize,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome.grid;
        non_null_out(written)?;
        let n = g.voxel_count() as usize;
        put(written, n)?;
        if n > capacity {
            return Err(Failure::new(
                VkStatus::BufferTooSmall,
                format!("the grid has {n} voxels but there is room for {capacity}"),
            ));
        }
        let out = slice_mut(coords, 3 * n, "coords")?;
        for (k, c) in g.voxels().enumerate() {
            out[3 * k..3 * k + 3].copy_from_slice(&c);
        }
        Ok(())
    })
}

/// `vk_meta_type`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VkMetaType {
    Text = 0,
    Int = 1,
    Real = 2,
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_metadata_count(grid: *const VkGrid, count: *mut usize) -> VkStatus {
    guard(|| put(count, borrow(grid, Kind::Grid)?.metadata.len()))
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_metadata_item(
    grid: *const VkGrid,
    index: usize,
    key: *mut *const c_char,
    meta_type: *mut VkMetaType,
    text: *mut *const c_char,
    integer: *mut i64,
    real: *mut f64,
) -> VkStatus {
    guard(|| {
        let g = borrow(grid, Kind::Grid)?;
        let n = g.metadata.len();
        let (k, value, as_text) = g.metadata.get(index).ok_or_else(|| {
            invalid(format!(
                "metadata item {index} is out of range: the grid has {n}"
            ))
        })?;
        put(key, k.as_ptr())?;
        put(text, as_text.as_ptr())?;
        match value {
            MetaValue::Text(_) => put(meta_type, VkMetaType::Text),
            MetaValue::Int(v) => {
                put(integer, *v)?;
                put(meta_type, VkMetaType::Int)
            }
            MetaValue::Real(v) => {
                put(real, *v)?;
                put(meta_type, VkMetaType::Real)
            }
        }
    })
}

/// `vk_grid_class`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VkGridClass {
    Voxels = 0,
    LevelSet = 1,
    UnsignedDistance = 2,
}

/// `vk_export_info`: one grid of a write, described.
#[repr(C)]
pub struct VkExportInfo {
    pub name: [c_char; 256],
    /// 0 bool, 1 float, 2 vec3s.
    pub value_type: c_int,
    /// 0 none, 1 fog volume, 2 level set.
    pub grid_class: c_int,
    /// 0 none, 1 covariant normalize, 2 invariant.
    pub vector_type: c_int,
    pub leaf_count: usize,
    pub tile_count: usize,
    pub background: f32,
    pub tiles_active: c_int,
    pub tile_value: f32,
}

/// The write options of `options`, or the defaults when it is NULL.
fn write_options_of(options: *const VkOptions) -> std::result::Result<WriteOptions, Failure> {
    if options.is_null() {
        return Ok(WriteRequest::default().options());
    }
    Ok(options_of(options)?.write.options())
}

/// The grid `index` of the write of `grid` as `options` choose its grids.
fn exported(
    grid: *const VkGrid,
    options: *const VkOptions,
    index: usize,
) -> std::result::Result<ExportedGrid, Failure> {
    let g = &borrow(grid, Kind::Grid)?.outcome;
    let mut one = g.export_grids(&write_options_of(options)?, Some(index))?;
    Ok(one.pop().expect("the grid asked for"))
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_export_count(
    grid: *const VkGrid,
    options: *const VkOptions,
    count: *mut usize,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome;
        put(count, g.export_grid_count(&write_options_of(options)?)?)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_export_info(
    grid: *const VkGrid,
    options: *const VkOptions,
    index: usize,
    info: *mut VkExportInfo,
) -> VkStatus {
    guard(|| {
        non_null_out(info)?;
        let e = exported(grid, options, index)?;
        let mut name = [0 as c_char; 256];
        for (d, b) in name.iter_mut().zip(e.name.bytes().take(255)) {
            *d = b as c_char;
        }
        let code = |v: Option<&str>, names: [&str; 2]| {
            v.and_then(|v| names.iter().position(|n| *n == v))
                .map_or(0, |i| i as c_int + 1)
        };
        put(
            info,
            VkExportInfo {
                name,
                value_type: ["bool", "float", "vec3s"]
                    .iter()
                    .position(|t| *t == e.value_type)
                    .unwrap_or(0) as c_int,
                grid_class: code(e.class, ["fog volume", "level set"]),
                vector_type: code(e.vector_type, ["covariant normalize", "invariant"]),
                leaf_count: e.leaf_origins.len() / 3,
                tile_count: e.tiles.len() / 4,
                background: e.background,
                tiles_active: c_int::from(e.tiles_active),
                tile_value: e.tile_value,
            },
        )
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_export_arrays(
    grid: *const VkGrid,
    options: *const VkOptions,
    index: usize,
    leaf_origins: *mut i32,
    masks: *mut u64,
    values: *mut f32,
    tiles: *mut i32,
) -> VkStatus {
    guard(|| {
        let e = exported(grid, options, index)?;
        fn copy<T: Copy>(dst: *mut T, src: &[T], what: &str) -> Status {
            if !src.is_empty() {
                slice_mut(dst, src.len(), what)?.copy_from_slice(src);
            }
            Ok(())
        }
        copy(leaf_origins, &e.leaf_origins, "leaf_origins")?;
        copy(masks, &e.masks, "masks")?;
        copy(values, &e.values, "values")?;
        copy(tiles, &e.tiles, "tiles")
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_get_class(
    grid: *const VkGrid,
    kind: *mut VkGridClass,
    background: *mut f32,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome;
        non_null_out(kind)?;
        non_null_out(background)?;
        let (k, b) = match &g.distances {
            None => (VkGridClass::Voxels, 0.0),
            Some(d) if d.interior.is_some() => (VkGridClass::LevelSet, d.background),
            Some(d) => (VkGridClass::UnsignedDistance, d.background),
        };
        put(kind, k)?;
        put(background, b)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_copy_values(
    grid: *const VkGrid,
    first: usize,
    count: usize,
    values: *mut f32,
) -> VkStatus {
    guard(|| {
        let g = &borrow(grid, Kind::Grid)?.outcome;
        let Some(d) = &g.distances else {
            return Err(invalid(
                "the grid holds voxels, not distances: it has no values to copy",
            ));
        };
        let leaves = leaf_range(&g.grid, first, count)?;
        let out = slice_mut(values, LEAF_VOXELS * count, "values")?;
        for (k, leaf) in leaves.iter().enumerate() {
            let dst = &mut out[LEAF_VOXELS * k..LEAF_VOXELS * (k + 1)];
            // What OpenVDB reads at inactive voxels: minus the background inside.
            let inside = d
                .interior
                .as_ref()
                .map_or([0; 8], |i| i.block_mask(leaf.origin));
            for (n, v) in dst.iter_mut().enumerate() {
                *v = if inside[n / 64] >> (n % 64) & 1 == 1 {
                    -d.background
                } else {
                    d.background
                };
            }
            let own = leaf.value.as_ref().expect("distances");
            for n in leaf.offsets() {
                dst[n] = own[n];
            }
        }
        Ok(())
    })
}

/// The first coordinate of `v` as a block origin: a multiple of `edge`, or an error.
fn block_origin(v: &[i32], edge: i64, what: &str) -> std::result::Result<Coord, Failure> {
    let origin = [0, 1, 2].map(|a| i64::from(v[a]));
    if origin.iter().any(|c| c.rem_euclid(edge) != 0) {
        return Err(invalid(format!(
            "{what} at {origin:?} is not on a multiple of {edge}"
        )));
    }
    Ok(origin)
}

#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn vk_grid_from_leaves(
    voxel_size: f64,
    origin: *const f64,
    leaf_count: usize,
    leaf_origins: *const i32,
    masks: *const u64,
    tile_count: usize,
    tile_origins: *const i32,
    tile_edges: *const i32,
    out: *mut *mut VkGrid,
) -> VkStatus {
    guard(|| {
        non_null_out(out)?;
        crate::pipeline::request::positive("voxel_size", voxel_size)?;
        let o = slice(origin, 3, "origin")?;
        if !o.iter().all(|v| v.is_finite()) {
            return Err(invalid(format!("the origin {o:?} must be finite numbers")));
        }
        let leaf_origins = slice(leaf_origins, 3 * leaf_count, "leaf_origins")?;
        let masks = slice(masks, 8 * leaf_count, "masks")?;
        let tile_origins = slice(tile_origins, 3 * tile_count, "tile_origins")?;
        let tile_edges = slice(tile_edges, tile_count, "tile_edges")?;
        let bytes = (leaf_count as u64).saturating_mul(std::mem::size_of::<Leaf>() as u64 * 2);
        crate::system::check_fits(bytes, None, &format!("a grid of {leaf_count} leaves"))?;
        let transform = Transform::new(DVec3::new(o[0], o[1], o[2]), voxel_size);
        let mut leaves = Vec::with_capacity(leaf_count);
        for k in 0..leaf_count {
            let mut leaf = Leaf::new(
                block_origin(&leaf_origins[3 * k..], 8, "leaf")?,
                Channels::NONE,
            );
            leaf.mask.copy_from_slice(&masks[8 * k..8 * k + 8]);
            leaves.push(leaf);
        }
        let mut grid = SparseGrid::from_leaves(transform, Channels::NONE, leaves);
        for k in 0..tile_count {
            match tile_edges[k] {
                8 => grid.fill_leaf_block(block_origin(&tile_origins[3 * k..], 8, "tile")?),
                128 => grid.fill_node_block(block_origin(&tile_origins[3 * k..], 128, "tile")?),
                e => {
                    return Err(invalid(format!(
                        "tile {k} has edge {e}: tiles are 8 or 128"
                    )));
                }
            }
        }
        grid.prune();
        grid.compact();
        let outcome = Outcome::from_voxels(grid, "the caller's leaves");
        hand_out(VkGrid::from(outcome), Kind::Grid, out)
    })
}

#[unsafe(no_mangle)]
pub extern "C" fn vk_grid_free(grid: *mut VkGrid) -> VkStatus {
    guard(|| release(grid, Kind::Grid))
}
