//! Spectrace's renderer: a scene file goes in, a validated scene is assembled, the estimator the
//! effects analysis chooses (light tracer, path tracer or BDPT) renders it, and a linear EXR, an
//! sRGB PNG and a JSON sidecar come out.
//!
//! This crate is thin glue over the others (the data flow of `docs/ARCHITECTURE.md`): [`Scene`]
//! reads and validates the JSON (errors name the file, line, column and field path) and adds area
//! lights' surfaces and glowing objects to the scene, [`render_scene`] runs the effects analysis,
//! chooses the integrator ([`choose_integrator`]), checks that light can reach the camera, renders
//! on threads with a progress bar and writes the outputs normalised per estimator
//! ([`Normalisation`]), and [`merge_parts`] turns the partial films of a sharded render into the
//! same image a single machine would make, bit for bit. Every render also says how accurate it
//! is ([`AccuracyEstimate`] in the sidecar, from the tracer's per-chunk moments), can render to a
//! target error (`--target-error`), and [`pilot::estimate`] predicts the time to a target per
//! estimator before rendering. The key design decision: one render path for every estimator
//! ([`with_integrator`]), so sharding, time budgets, targets, probes and outputs work the same for
//! all, and the estimators are named and built in one place only (the `integrators` module). The
//! `spectrace` binary exposes it; the xtask's `render` subcommand calls it.
//! The accuracy report is not here: it is an experiment harness with its own crate,
//! `spectrace-lab`, so programs that render do not link its plotting library; this crate keeps
//! the timed measurement both it and `spectrace bench` use ([`render_xyz`],
//! [`integrator_benchmark`]). Nothing but `spectrace-lab`, `xtask` and the tests depend on this
//! crate.
//!
//! The modules follow the jobs, in the order a render meets them: `import` (Mitsuba XML scenes
//! into the native scene, [`import_mitsuba`]) and `convert`, `scene` (the typed scene both front
//! ends produce in `scene::model`, the JSON reader in `scene::json`, the assembly in
//! `scene::assembly`; [`Scene::features`], the one place its features are found), `options` (overrides,
//! errors), `plan` (estimator, effects, plan, normalisation), `integrators` (the estimators, from
//! the tracer's registry), `probe`, `warnings`, `run`
//! ([`render_scene`] in named steps), `progress`, `write` and `output` (the files and their
//! encoding), `report` (the sidecar), `sensors` and `sensor_output`, `observers` (eye
//! positions: cylindrical illuminance, melanopic EDI, UGR), `part`, `part_receivers` and `shard`
//! (part files, the sensors' and observers' shares, and [`merge_parts`]), `cluster` (`--shard
//! auto` from a scheduler's environment), `bench`, [`pilot`], [`measured`] (`auto` chosen by a pilot of
//! each complete estimator), [`cli`], and `files` (bounded reads, atomic writes). Everything
//! public is re-exported here, at the crate's root.

mod bench;
pub mod cli;
mod cluster;
mod convert;
mod files;
mod import;
mod integrators;
pub mod measured;
mod observers;
mod options;
mod output;
mod part;
mod part_receivers;
pub mod pilot;
mod plan;
mod probe;
mod progress;
mod report;
mod run;
mod say;
mod scene;
mod sensor_output;
mod sensors;
mod shard;
mod warnings;
mod write;

pub use bench::{
    EffectsBenchmarkRow, IntegratorBenchmarkRow, IntegratorTiming, effects_benchmark,
    integrator_benchmark, render_xyz,
};
pub use cluster::shard_from_environment;
pub use convert::convert;
pub use files::{
    MAX_OUTPUT_NAME_BYTES, MAX_PART_BYTES, MAX_SCENE_BYTES, check_no_input_replaced,
    check_output_name, prepare_out_dir, read_bounded, same_file, write_atomically,
};
pub use import::{
    ImportError, ImportNote, Imported, import_mitsuba, import_mitsuba_with, is_mitsuba_scene,
};
pub use integrators::{tracer_scene, with_integrator};
pub use observers::{
    GlareTerm, ObservedLux, ObserverReport, guth_position_index, observer_summary,
    render_observers, unified_glare_rating,
};
pub use options::{RenderError, RenderOptions};
pub use output::{EncodedImage, OUTPUT_BYTES_PER_PIXEL, encode_image, write_exr, write_png};
pub use part::{PARTIAL_VERSION, PartialFilm};
pub use part_receivers::{ReceiversPart, SensorDefinition};
pub use plan::{
    MAX_THREADS, Normalisation, choose_integrator, decide_effects, normalisation, plan_for,
    plan_with,
};
pub use probe::{PROBE_BEAMS, PROBE_SECONDS, ProbeOutcome, probe, probe_with};
pub use report::{
    AccuracyEstimate, LightReport, LuminaireReport, PREDICTED_ERRORS, RenderReport, duration,
};
pub use run::{InMemoryRender, render_file, render_in_memory, render_scene};
pub use scene::{
    DEFAULT_OBSERVER_SPP, DEFAULT_SENSOR_FLOOR_LUX, DEFAULT_SENSOR_SPP, DEFAULT_SPP,
    EffectsSettings, ErrorImage, LoadOptions, Object, OutputSettings, Scene, SceneError, SceneFile,
    SensorIntegrator, Settings, SettingsGiven, check_target_error,
};
pub use sensor_output::{
    MAX_SENSOR_CELLS, SensorGrid, SensorSummary, sensor_colour, write_sensor_files,
};
pub use sensors::{
    FILLED_BY_IMAGE, FILLED_BY_LIGHT_PASS, FILLED_BY_PATH_PASS, PassShare, SensorEstimate,
    SensorReport, SensorSource, check_sensor_names, planned_sensor_outputs, sensor_grid,
    sensor_integrator, sensor_pass, sensor_pass_path, sensor_plan, sensor_summary,
    worst_cell_error, write_sensors,
};
pub use shard::merge_parts;
pub use write::{Written, image, write_outputs};
