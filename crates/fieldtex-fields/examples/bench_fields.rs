//! Field design benchmark: 128×128 grid, whorl preset, 512² pixel field.
//!
//! `cargo run --release -p fieldtex-fields --example bench_fields [-- REPEATS]`
//!
//! Every interactive timing is what a front end sees, called from the main thread (not
//! a rayon worker): the edit, then `FieldDesign::solve_and_sample_into` — the re-solve
//! and the 512² pixel sample into a kept buffer as one job in the rayon pool. Prints medians as
//! `BENCH <name> median_ms=<value>` lines:
//! - `field_factor`: from nothing to a factored design: DEC operators, assembly, symbolic
//!   analysis, the preset's strokes, numeric factorisation (once per domain);
//! - `field_full_solve`: design → pixel field on the factored design: every singularity
//!   re-placed (all model fields recomputed), solve, sample 512²;
//! - `field_move_singularity`: move one wedge, re-solve (right-hand side only), sample;
//! - `field_add_stroke`: add one ~250 px stroke (~250 changed edges: one multiple-rank
//!   factor update, see `FieldDesignOptions::rank1_update_limit`), solve, sample;
//! - `field_move_stroke`: move that stroke by 2–6 px (`set_stroke`: the factor kept
//!   from before the stroke was added is copied and gets one multiple-rank update with
//!   the moved stroke's edges, cheaper than updating the edges gaining weight and
//!   downdating those losing it; see `design_factor`), solve, sample;
//! - `field_remove_stroke`: remove it (a copy of that kept factor), solve, sample;
//! - `field_drag_stroke_1px` (and its 90th percentile `_p90`): a mouse drag, the same
//!   stroke moved by 1 px per event, 12 events: each event's edit (direct updates and
//!   downdates of the edges that changed, or a checkpoint restore plus an update,
//!   whichever changes fewer edges), solve, sample;
//! - `field_add_stroke_refactor`: add with `rank1_update_limit = 0` (numeric
//!   refactorisation with the kept symbolic analysis; the behaviour before the limit
//!   was raised to 640 edges);
//! - `field_add_short_stroke`: a ~18 px stroke (about 40 edges);
//! - `field_numeric_refactor`: the numeric factorisation alone;
//! - `field_move_singularity_solve_only` / `field_sample_512`: the move split into
//!   re-solve and pixel sampling.
//!
//! Targets (issue 3): move < 20 ms, full < 50 ms. Timings depend on machine load; the
//! first line reports the load average where /proc/loadavg exists.

use std::time::Instant;

use fieldtex_fields::orientation_field::sample_plane_into;
use fieldtex_fields::presets::preset;
use fieldtex_fields::{Domain, FieldDesign, Stroke};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let repeats: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(15);
    if let Ok(load) = std::fs::read_to_string("/proc/loadavg") {
        println!("info: load average {}", load.trim());
    }
    println!("info: rayon threads {}", rayon::current_num_threads());
    let size = 512usize;
    let file = preset("whorl", size as f64, size as f64, 128).unwrap();
    let grid = file.plane_grid().unwrap();
    let (symmetry, options) = (file.symmetry().unwrap(), file.options());

    let mut t_factor = Vec::new();
    let mut design = None;
    for _ in 0..repeats.clamp(1, 7) {
        let t = Instant::now();
        let mut d = FieldDesign::new(Domain::Plane(grid), symmetry, options.clone()).unwrap();
        for s in file.stroke_list() {
            d.add_stroke(s).unwrap();
        }
        d.refactor_if_needed().unwrap();
        t_factor.push(ms(t));
        design = Some(d);
    }
    let mut d = design.unwrap();
    println!("info: {} unknowns (edges), matrix nnz {}", d.dec().n_edges(), d.base_matrix().nnz());
    let singularities = file.singularity_list().unwrap();
    let mut buf: Vec<[f32; 2]> = Vec::new();
    let ids: Vec<_> = singularities.iter().map(|s| d.add_singularity(*s).unwrap()).collect();

    let mut t_full = Vec::new();
    for _ in 0..repeats {
        let t = Instant::now();
        for (id, s) in ids.iter().zip(&singularities) {
            d.set_singularity(*id, *s).unwrap();
        }
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_full.push(ms(t));
        assert_eq!(buf.len(), size * size);
    }

    let mut t_move = Vec::new();
    let p0 = singularities[0].position;
    for k in 0..repeats {
        let p = [
            p0[0] + 3.0 * ((k % 5) as f64 - 2.0) + 0.31,
            p0[1] + 2.0 * ((k % 3) as f64 - 1.0) + 0.37,
            0.0,
        ];
        let t = Instant::now();
        d.move_singularity(ids[0], p).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_move.push(ms(t));
        assert_eq!(buf.len(), size * size);
    }

    let mut t_solve_only = Vec::new();
    let mut t_sample = Vec::new();
    for k in 0..repeats {
        let p = [p0[0] + 2.0 * ((k % 4) as f64 - 1.5) + 0.13, p0[1] + 0.29, 0.0];
        let t = Instant::now();
        d.move_singularity(ids[0], p).unwrap();
        let f = d.solve().unwrap();
        t_solve_only.push(ms(t));
        let t = Instant::now();
        sample_plane_into(&d, &f, size, size, &mut buf).unwrap();
        t_sample.push(ms(t));
        assert_eq!(buf.len(), size * size);
    }

    let stroke_at = |k: usize| {
        let y = 150.0 + 10.0 * k as f64;
        Stroke::from_pixels(&[[60.0, y], [200.0, y - 20.0], [300.0, y + 10.0]])
    };
    let (mut t_stroke, mut t_move_stroke, mut t_remove_stroke) =
        (Vec::new(), Vec::new(), Vec::new());
    let updates_before = d.rank1_update_count();
    let refactors_before = d.refactor_count();
    let restores_before = d.checkpoint_restore_count();
    for k in 0..repeats {
        let t = Instant::now();
        let sid = d.add_stroke(stroke_at(k)).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_stroke.push(ms(t));
        // Drag it by a few pixels (a front end re-solves on every mouse event).
        let dy = 2.0 + (k % 3) as f64 * 2.0;
        let moved = Stroke::from_pixels(&[
            [60.0, 150.0 + 10.0 * k as f64 + dy],
            [200.0, 130.0 + 10.0 * k as f64 + dy],
            [300.0, 160.0 + 10.0 * k as f64 + dy],
        ]);
        let t = Instant::now();
        d.set_stroke(sid, moved).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_move_stroke.push(ms(t));
        let t = Instant::now();
        d.remove_stroke(sid).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_remove_stroke.push(ms(t));
        assert_eq!(buf.len(), size * size);
    }
    println!(
        "info: long strokes: {} rank-1 updates, {} checkpoint restores and {} refactorisations for {repeats} additions + moves + removals",
        d.rank1_update_count() - updates_before,
        d.checkpoint_restore_count() - restores_before,
        d.refactor_count() - refactors_before
    );
    // A mouse drag: the same stroke moved 1 px per event (a front end re-solves on each),
    // 12 events per repeat; the edit path is chosen by edge counts (design_factor).
    let mut t_drag_1px = Vec::new();
    for k in 0..repeats {
        let y = 150.0 + 10.0 * k as f64;
        let sid = d.add_stroke(stroke_at(k)).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        for step in 1..=12 {
            let dy = step as f64;
            let moved = Stroke::from_pixels(&[
                [60.0, y + dy],
                [200.0, y - 20.0 + dy],
                [300.0, y + 10.0 + dy],
            ]);
            let t = Instant::now();
            d.set_stroke(sid, moved).unwrap();
            d.solve_and_sample_into(size, size, &mut buf).unwrap();
            t_drag_1px.push(ms(t));
        }
        d.remove_stroke(sid).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
    }
    // A short stroke (~18 px, about 40 edges).
    let mut t_short = Vec::new();
    let updates_short = d.rank1_update_count();
    for k in 0..repeats {
        let y = 150.0 + 10.0 * k as f64;
        let t = Instant::now();
        let sid = d.add_stroke(Stroke::from_pixels(&[[60.0, y], [78.0, y - 3.0]])).unwrap();
        d.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_short.push(ms(t));
        assert_eq!(buf.len(), size * size);
        d.remove_stroke(sid).unwrap();
        d.refactor_if_needed().unwrap();
    }
    println!(
        "info: short strokes: {} rank-1 updates for {repeats} additions + removals",
        d.rank1_update_count() - updates_short
    );
    println!("info: {} refactorisations in all", d.refactor_count());

    let mut refactoring = FieldDesign::new(
        Domain::Plane(grid),
        symmetry,
        fieldtex_fields::FieldDesignOptions { rank1_update_limit: 0, ..options.clone() },
    )
    .unwrap();
    for s in file.stroke_list() {
        refactoring.add_stroke(s).unwrap();
    }
    for s in &singularities {
        refactoring.add_singularity(*s).unwrap();
    }
    refactoring.solve().unwrap();
    let mut t_stroke_refactor = Vec::new();
    let mut t_refactor = Vec::new();
    for k in 0..repeats {
        let t = Instant::now();
        let sid = refactoring.add_stroke(stroke_at(k)).unwrap();
        refactoring.solve_and_sample_into(size, size, &mut buf).unwrap();
        t_stroke_refactor.push(ms(t));
        assert_eq!(buf.len(), size * size);
        refactoring.remove_stroke(sid).unwrap();
        let t = Instant::now();
        refactoring.refactor_if_needed().unwrap();
        t_refactor.push(ms(t));
    }

    println!("BENCH field_factor median_ms={:.2}", median(t_factor));
    println!("BENCH field_full_solve median_ms={:.2}", median(t_full));
    println!("BENCH field_move_singularity median_ms={:.2}", median(t_move));
    println!("BENCH field_move_singularity_solve_only median_ms={:.2}", median(t_solve_only));
    println!("BENCH field_sample_512 median_ms={:.2}", median(t_sample));
    println!("BENCH field_add_stroke median_ms={:.2}", median(t_stroke));
    println!("BENCH field_move_stroke median_ms={:.2}", median(t_move_stroke));
    println!("BENCH field_remove_stroke median_ms={:.2}", median(t_remove_stroke));
    println!("BENCH field_drag_stroke_1px median_ms={:.2}", median(t_drag_1px.clone()));
    t_drag_1px.sort_by(|a, b| a.total_cmp(b));
    println!(
        "BENCH field_drag_stroke_1px_p90 median_ms={:.2}",
        t_drag_1px[t_drag_1px.len() * 9 / 10]
    );
    println!("BENCH field_add_stroke_refactor median_ms={:.2}", median(t_stroke_refactor));
    println!("BENCH field_add_short_stroke median_ms={:.2}", median(t_short));
    println!("BENCH field_numeric_refactor median_ms={:.2}", median(t_refactor));
}
