//! The memory estimate of a volume job (`Family::memory`) counts the
//! cumulative optical depth's checkpoint table, one entry per outer node of
//! V-E and V-L, beside the rule's node table. Measured here by a counting
//! allocator around the real evaluation: the peak bytes allocated by a job of I_E above those of a job
//! of tau alone (the same rule, budget and scene: tau's integral holds the
//! node table, I_E's the table and the checkpoints) against the estimate's
//! difference. A binary of its own with this one test: the counting
//! allocator counts the whole process, so nothing else may allocate while it
//! measures.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use lightquad::family::{Family, Method};
use lightquad::volume::experiment::{SceneSpec, Volume, VolumeQuantity};
use lightquad::volume::tracking::Tracker;

/// Counts the bytes held and the most held since the last reset.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is passed to the system allocator unchanged; the
// counters are only read.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = HELD.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        HELD.fetch_sub(layout.size(), Ordering::SeqCst);
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The peak bytes held while `f` runs, above those held before it.
fn peak_of(f: impl FnOnce()) -> f64 {
    let before = HELD.load(Ordering::SeqCst);
    PEAK.store(before, Ordering::SeqCst);
    f();
    (PEAK.load(Ordering::SeqCst) - before) as f64
}

#[test]
fn the_memory_estimate_counts_the_depth_checkpoints() {
    // The constant sphere of VALID in tests/it/runner.rs, emitting, cumulative
    // depth (the default).
    let spec: SceneSpec = serde_json::from_value(serde_json::json!({
        "ray": {"origin": [-3.0, 0.3, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": 2.0},
        "emission": {"type": "constant", "c": 1.0}
    }))
    .expect("scene");
    let built = Volume::build(&spec).expect("built");
    let n = 200_000;
    for rule in ["trapezoid", "gauss-legendre", "gauss-kronrod"] {
        let method: Method<Tracker> =
            serde_json::from_value(serde_json::json!({ "rule": rule })).expect("rule");
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(1);
        let run = |q: VolumeQuantity, rng: &mut rand_pcg::Pcg64| {
            peak_of(|| {
                Volume::evaluate(&built, &method, n, rng, &[q]).expect("evaluates");
            })
        };
        // Node tables are cached between calls: warm them first.
        run(VolumeQuantity::Emission, &mut rng);
        let tau = run(VolumeQuantity::Tau, &mut rng);
        let emission = run(VolumeQuantity::Emission, &mut rng);
        let measured = emission - tau;
        let estimate = Volume::memory(&built, &method, n, VolumeQuantity::Emission)
            - Volume::memory(&built, &method, n, VolumeQuantity::Tau);
        let ratio = estimate / measured;
        eprintln!(
            "{rule} n = {n}: checkpoints estimated {estimate:.3e} B, measured {measured:.3e} B \
             (tau alone {tau:.3e} B), ratio {ratio:.2}"
        );
        assert!(
            (1.0 / 1.5..=1.5).contains(&ratio),
            "{rule} at n = {n}: estimate {estimate:.3e} B against {measured:.3e} B measured \
             (ratio {ratio:.2})"
        );
    }
}
