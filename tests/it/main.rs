//! The integration tests: one test binary, one module per area, each
//! asserting against an independent reference (a closed form, a cited
//! high-precision table in `tests/data/`, another method).
//!
//! One binary links the crate once: `cargo test --release` compiles this
//! crate and two that own their process, `tests/memory_checkpoints.rs` (a
//! counting global allocator) and `tests/memory_peak.rs` (a child's peak
//! resident memory, which counts its spawner's). Tests here share one process,
//! so none may change process-wide state (the working folder, environment
//! variables, rayon's global pool); scratch folders come from
//! [`common::scratch`], unique per call.

mod common;

mod anywhere;
mod coverage;
mod coverage_small_n;
mod domains;
mod estimate_honesty;
mod exchange_exact;
mod exchange_family;
mod external;
mod family_plugin;
mod fixed_order;
mod furnace_family;
mod gauss_legendre;
mod gauss_legendre_peers;
mod genz_malik;
mod halton_dims;
mod html_report;
mod input_leftovers;
mod integral_bundled;
mod integral_expr;
mod integral_family;
mod line_sum_par;
mod memory_estimate;
mod mitsuba;
mod output_safety;
mod parallel;
mod product_value;
mod properties;
mod reference_bounds;
mod rendering_brdf;
mod rendering_contour;
mod rendering_convergence;
mod rendering_emitters;
mod rendering_exact;
mod rendering_extreme;
mod rendering_family;
mod rendering_forms;
mod rendering_furnace;
mod rendering_mis;
mod rules;
mod runner;
mod sobol_dims;
mod spec_fuzz;
mod sum_lanes;
mod summary_compare;
mod testing_api;
mod testing_light;
mod tracking_cost;
mod tracking_diagnostic;
mod unit_table;
mod verdicts;
mod volume;
mod volume_emission;
mod volume_estimators;
mod volume_media;
mod whitted_extreme;
mod whitted_family;
mod whitted_outputs;
mod whitted_pixel;
mod whitted_shading;
