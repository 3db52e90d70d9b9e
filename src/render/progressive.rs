//! Progressive quality under a frame-time budget (pure logic, no GPU).
//!
//! Drawing the volume at full quality takes seconds on CPU adapters (SwiftShader, lavapipe),
//! so the viewport never draws it in one frame. A cost model learnt from measured frame
//! intervals — seconds per pixel·slice of volume work, plus a fixed overhead per frame (the UI,
//! compositing and presenting, which on a CPU adapter at 1920×1080 is a good part of every
//! frame) — picks:
//! - a **preview** (lower resolution and fewer slices) rendered in one frame whenever the view
//!   changes, sized to the interactive budget;
//! - a **refinement** at full quality once the view is still, accumulated back to front over
//!   several frames in chunks of slices that each fit the budget ("over" compositing is
//!   associative, so chunks add up to exactly the full image), shown when complete.

use std::ops::Range;

/// Work the planner asks for this frame.
#[derive(Clone, Debug, PartialEq)]
pub struct JobPlan {
    /// Accumulation target: 0 for previews, 1 for refinement.
    pub target: usize,
    /// Target size in pixels.
    pub size: [u32; 2],
    /// Slices in the whole image.
    pub total: u32,
    /// Slices to draw now.
    pub range: Range<u32>,
    /// Whether this starts a new image.
    pub clear: bool,
}

/// The quality of an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quality {
    /// Image size in pixels.
    pub size: [u32; 2],
    /// Slice count.
    pub slices: u32,
    /// Whether this is the full quality for the current view.
    pub full: bool,
}

impl std::fmt::Display for Quality {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let level = if self.full { "full" } else { "preview" };
        write!(
            f,
            "{level} {}x{}x{}",
            self.size[0], self.size[1], self.slices
        )
    }
}

/// What to do this frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePlan {
    /// Volume work to record, if any.
    pub job: Option<JobPlan>,
    /// Target to show (none before the first image).
    pub display: Option<usize>,
    /// Quality of the image shown after this frame.
    pub shown: Option<Quality>,
    /// Fraction of the refinement done, while one is under way.
    pub refining: Option<f32>,
    /// Whether another frame is needed soon (work is under way).
    pub repaint: bool,
}

/// Frame-time budgets in seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// A preview frame (while dragging).
    pub interactive: f64,
    /// One refinement chunk.
    pub refine: f64,
    /// The whole refinement: on slow adapters the refined image's resolution drops (never
    /// below [`MIN_REFINE_SCALE`] of the viewport) so full quality arrives within this time.
    pub refine_total: f64,
}

impl Default for Budget {
    fn default() -> Self {
        Self {
            interactive: 0.1,
            refine: 0.25,
            refine_total: 1.6,
        }
    }
}

#[derive(Clone, Debug)]
struct Shown {
    key: u64,
    target: usize,
    quality: Quality,
}

#[derive(Clone, Debug)]
struct Refine {
    key: u64,
    size: [u32; 2],
    total: u32,
    next: u32,
}

/// The planner; keep one per viewport.
#[derive(Clone, Debug)]
pub struct Progressive {
    budget: Budget,
    cost: f64,
    /// Seconds every frame takes besides its volume work.
    overhead: f64,
    /// Recent frames with volume work: (pixel·slices, seconds).
    samples: std::collections::VecDeque<(f64, f64)>,
    pending: Option<(f64, f64)>,
    shown: Option<Shown>,
    refine: Option<Refine>,
    last_frame: Option<f64>,
}

/// Fewest slices a preview uses.
const MIN_PREVIEW_SLICES: u32 = 16;
/// Smallest preview resolution scale.
const MIN_PREVIEW_SCALE: f64 = 0.15;
/// Smallest resolution scale of the refined (full-quality) image.
pub const MIN_REFINE_SCALE: f64 = 0.25;
/// Frames the overhead is fitted over.
const SAMPLES: usize = 16;

impl Progressive {
    /// A planner starting from a guessed cost in seconds per pixel·slice.
    pub fn new(initial_cost: f64, budget: Budget) -> Self {
        Self {
            budget,
            cost: initial_cost.max(1e-12),
            overhead: 0.0,
            samples: std::collections::VecDeque::new(),
            pending: None,
            shown: None,
            refine: None,
            last_frame: None,
        }
    }

    /// Current cost estimate in seconds per pixel·slice.
    pub fn cost(&self) -> f64 {
        self.cost
    }

    /// Interval of the last measured frame that carried volume work, in seconds.
    pub fn last_frame_seconds(&self) -> Option<f64> {
        self.last_frame
    }

    /// Forgets the shown image (e.g. the GPU targets were lost).
    pub fn reset(&mut self) {
        self.shown = None;
        self.refine = None;
        self.pending = None;
    }

    /// Plans the frame at time `now` (seconds) for a view identified by `key` in a viewport of
    /// `viewport` pixels whose full quality is `full_slices`. While `interacting` (pointer held)
    /// no refinement starts, so dragging stays responsive.
    pub fn plan(
        &mut self,
        now: f64,
        key: u64,
        viewport: [u32; 2],
        full_slices: u32,
        interacting: bool,
    ) -> FramePlan {
        self.measure(now);
        let viewport = [viewport[0].max(1), viewport[1].max(1)];
        let full_slices = full_slices.max(1);

        let view_changed = self.shown.as_ref().is_none_or(|s| s.key != key);
        if view_changed {
            self.refine = None;
            let (size, slices) = self.preview_level(viewport, full_slices);
            let quality = Quality {
                size,
                slices,
                full: size == self.refine_size(viewport, full_slices) && slices == full_slices,
            };
            self.shown = Some(Shown {
                key,
                target: 0,
                quality,
            });
            return self.submit(
                now,
                JobPlan {
                    target: 0,
                    size,
                    total: slices,
                    range: 0..slices,
                    clear: true,
                },
                Some(0),
                None,
            );
        }
        let Some(shown) = self.shown.clone() else {
            unreachable!("set above")
        };
        if shown.quality.full || interacting {
            return FramePlan {
                job: None,
                display: Some(shown.target),
                shown: Some(shown.quality),
                refining: None,
                repaint: false,
            };
        }
        let size = self.refine_size(viewport, full_slices);
        let chunk_seconds = self.chunk_seconds();
        let refine = match &mut self.refine {
            Some(r) if r.key == key => r,
            slot => slot.insert(Refine {
                key,
                size,
                total: full_slices,
                next: 0,
            }),
        };
        let pixels = refine.size[0] as f64 * refine.size[1] as f64;
        let per_chunk = (chunk_seconds / (self.cost * pixels))
            .floor()
            .clamp(1.0, u32::MAX as f64) as u32;
        let start = refine.next;
        let end = start.saturating_add(per_chunk).min(refine.total);
        refine.next = end;
        let job = JobPlan {
            target: 1,
            size: refine.size,
            total: refine.total,
            range: start..end,
            clear: start == 0,
        };
        let progress = end as f32 / refine.total as f32;
        if end >= refine.total {
            let quality = Quality {
                size: refine.size,
                slices: refine.total,
                full: true,
            };
            self.shown = Some(Shown {
                key,
                target: 1,
                quality,
            });
            self.refine = None;
            self.submit(now, job, Some(1), None)
        } else {
            self.submit(now, job, Some(shown.target), Some(progress))
        }
    }

    fn submit(
        &mut self,
        now: f64,
        job: JobPlan,
        display: Option<usize>,
        refining: Option<f32>,
    ) -> FramePlan {
        let work =
            job.size[0] as f64 * job.size[1] as f64 * (job.range.end - job.range.start) as f64;
        self.pending = Some((now, work));
        FramePlan {
            job: Some(job),
            display,
            shown: self.shown.as_ref().map(|s| s.quality),
            refining,
            repaint: true,
        }
    }

    /// Learns the cost and the overhead from the interval since the last frame that carried
    /// work: the overhead is the intercept of a line fitted through recent frames of different
    /// sizes (previews and refinement chunks); the cost is what a frame took beyond it.
    fn measure(&mut self, now: f64) {
        let Some((then, work)) = self.pending.take() else {
            return;
        };
        let dt = now - then;
        if dt.is_nan() || dt <= 0.0 || work <= 0.0 {
            return;
        }
        self.last_frame = Some(dt);
        if self.samples.len() == SAMPLES {
            self.samples.pop_front();
        }
        self.samples.push_back((work, dt));
        self.fit_overhead();
        let sample = ((dt - self.overhead).max(0.5 * dt) / work).min(self.cost * 20.0);
        // Rise fast (stay responsive), fall slowly (don't trust one quick frame).
        let w = if sample > self.cost { 0.6 } else { 0.25 };
        self.cost = self.cost * (1.0 - w) + sample * w;
    }

    /// Least squares of seconds on work over the recent frames, when their sizes differ enough
    /// to tell a fixed part from a proportional one.
    fn fit_overhead(&mut self) {
        let n = self.samples.len() as f64;
        if n < 4.0 {
            return;
        }
        let (mw, md) = self
            .samples
            .iter()
            .fold((0.0, 0.0), |(a, b), &(w, d)| (a + w / n, b + d / n));
        let (var, cov) = self.samples.iter().fold((0.0, 0.0), |(v, c), &(w, d)| {
            (v + (w - mw) * (w - mw), c + (w - mw) * (d - md))
        });
        if var < (0.3 * mw).powi(2) * n || cov <= 0.0 {
            return;
        }
        let slope = cov / var;
        // Never more than half the quickest recent frame: a wrong fit must not make the cost
        // look small (the next chunk would then take seconds).
        let quickest = self
            .samples
            .iter()
            .map(|&(_, d)| d)
            .fold(f64::MAX, f64::min);
        let intercept = (md - slope * mw).clamp(0.0, 0.5 * quickest);
        self.overhead = 0.5 * self.overhead + 0.5 * intercept;
    }

    /// Seconds of volume work per refinement chunk: the chunk budget less the frame's
    /// overhead, so a refining frame stays near the budget.
    fn chunk_seconds(&self) -> f64 {
        (self.budget.refine - self.overhead).max(0.5 * self.budget.refine)
    }

    /// Resolution of the refined image: the viewport's, or less where the adapter could not
    /// refine it within the budget's total, counting each chunk frame's overhead.
    fn refine_size(&self, viewport: [u32; 2], full_slices: u32) -> [u32; 2] {
        let seconds = |scale: f64| {
            let work = self.cost
                * (viewport[0] as f64 * scale).round().max(1.0)
                * (viewport[1] as f64 * scale).round().max(1.0)
                * full_slices as f64;
            work + (work / self.chunk_seconds()).ceil() * self.overhead
        };
        let mut scale: f64 = 1.0;
        while scale > MIN_REFINE_SCALE && seconds(scale) > self.budget.refine_total {
            scale *= 0.95;
        }
        let scale = scale.max(MIN_REFINE_SCALE);
        viewport.map(|v| ((v as f64 * scale).round() as u32).max(1))
    }

    fn preview_level(&self, viewport: [u32; 2], full_slices: u32) -> ([u32; 2], u32) {
        let pixels = viewport[0] as f64 * viewport[1] as f64;
        let predicted = self.cost * pixels * full_slices as f64;
        // What the frame's overhead leaves of the interactive budget (a little at least).
        let budget = (self.budget.interactive - self.overhead).max(0.3 * self.budget.interactive);
        if predicted <= budget {
            return (viewport, full_slices);
        }
        let r = budget / predicted;
        let slices = ((full_slices as f64 * r.sqrt()).round() as u32)
            .clamp(MIN_PREVIEW_SLICES.min(full_slices), full_slices);
        let scale = (r * full_slices as f64 / slices as f64)
            .sqrt()
            .clamp(MIN_PREVIEW_SCALE, 1.0);
        let size = viewport.map(|v| ((v as f64 * scale).round() as u32).max(1));
        (size, slices)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const VIEW: [u32; 2] = [800, 600];

    /// Simulates an adapter of a given true cost; returns frames until full quality and the
    /// longest frame.
    fn run_until_full(p: &mut Progressive, true_cost: f64, key: u64, t: &mut f64) -> (usize, f64) {
        run_with_overhead(p, true_cost, 0.0, VIEW, key, t)
    }

    /// Like `run_until_full` on an adapter whose every frame also takes `overhead` seconds.
    fn run_with_overhead(
        p: &mut Progressive,
        true_cost: f64,
        overhead: f64,
        view: [u32; 2],
        key: u64,
        t: &mut f64,
    ) -> (usize, f64) {
        let mut longest: f64 = 0.0;
        for frame in 1..1000 {
            let plan = p.plan(*t, key, view, 128, false);
            let work = plan.job.as_ref().map_or(0.0, |j| {
                j.size[0] as f64 * j.size[1] as f64 * (j.range.end - j.range.start) as f64
            });
            let dt = (overhead + work * true_cost).max(0.016);
            longest = longest.max(dt);
            *t += dt;
            if plan.shown.is_some_and(|q| q.full) && plan.job.is_none() {
                return (frame, longest);
            }
        }
        panic!("never reached full quality");
    }

    #[test]
    fn slow_adapter_gets_previews_then_chunked_refinement() {
        // SwiftShader-like: 4 s for the full image in one go.
        let true_cost = 4.0 / (800.0 * 600.0 * 128.0);
        let mut p = Progressive::new(true_cost / 4.0, Budget::default());
        let mut t = 0.0;
        let (_frames, _) = run_until_full(&mut p, true_cost, 1, &mut t);
        // Once the cost is learnt, a new view's frames all stay near the budget.
        let t0 = t;
        let (frames, longest) = run_until_full(&mut p, true_cost, 2, &mut t);
        assert!(longest < 0.3, "longest frame {longest}");
        assert!(
            frames > 5,
            "refinement must be spread over frames, got {frames}"
        );
        assert!(t - t0 < 2.0, "full quality after {:.2} s", t - t0);
        assert!(
            (p.cost() / true_cost - 1.0).abs() < 0.5,
            "learnt {} vs {true_cost}",
            p.cost()
        );
    }

    #[test]
    fn the_frame_overhead_is_learnt_and_counted_in_the_refinement() {
        // SwiftShader at 1920×1080: the cloud's box is 1200×860 px, 12 s at full resolution
        // in one go, and every frame costs 0.1 s besides its volume work.
        let view = [1200, 860];
        let true_cost = 12.0 / (1200.0 * 860.0 * 128.0);
        let overhead = 0.1;
        let mut p = Progressive::new(true_cost / 3.0, Budget::default());
        let mut t = 0.0;
        // A few views (drags and refinements) to learn from.
        for key in 1..4 {
            run_with_overhead(&mut p, true_cost, overhead, view, key, &mut t);
        }
        // Capped at half the quickest frame, the estimate errs low, never high.
        assert!(
            p.overhead > 0.4 * overhead && p.overhead <= overhead,
            "learnt overhead {}",
            p.overhead
        );
        let t0 = t;
        let (_, longest) = run_with_overhead(&mut p, true_cost, overhead, view, 9, &mut t);
        assert!(t - t0 <= 2.0, "full quality after {:.2} s", t - t0);
        assert!(longest < 0.35, "longest frame {longest}");
        // Ignoring the overhead (the planner before it was modelled) took 4 s here.
        let mut naive = Progressive::new(true_cost, Budget::default());
        naive.overhead = 0.0;
        let predicted_naive = naive.refine_size(view, 128);
        let size = p.refine_size(view, 128);
        assert!(
            size[0] < predicted_naive[0],
            "{size:?} vs {predicted_naive:?}"
        );
    }

    #[test]
    fn fast_adapter_shows_full_quality_at_once() {
        let true_cost = 1e-10;
        let mut p = Progressive::new(true_cost, Budget::default());
        let plan = p.plan(0.0, 1, VIEW, 128, false);
        assert_eq!(
            plan.shown,
            Some(Quality {
                size: VIEW,
                slices: 128,
                full: true
            })
        );
        let plan = p.plan(0.02, 1, VIEW, 128, false);
        assert!(plan.job.is_none() && !plan.repaint);
    }

    #[test]
    fn chunks_cover_every_slice_exactly_once() {
        let mut p = Progressive::new(1e-7, Budget::default());
        let mut t = 0.0;
        p.plan(t, 9, VIEW, 100, false);
        let mut covered = Vec::new();
        loop {
            t += 0.1;
            let plan = p.plan(t, 9, VIEW, 100, false);
            match plan.job {
                Some(j) => {
                    assert_eq!(j.target, 1);
                    assert_eq!(j.clear, covered.is_empty());
                    covered.extend(j.range);
                }
                None => break,
            }
        }
        assert_eq!(covered, (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn view_change_restarts_and_interaction_defers_refinement() {
        let mut p = Progressive::new(1e-7, Budget::default());
        let a = p.plan(0.0, 1, VIEW, 128, false);
        assert_eq!(a.job.as_ref().unwrap().target, 0);
        assert!(!a.shown.unwrap().full);
        let held = p.plan(0.1, 1, VIEW, 128, true);
        assert!(held.job.is_none() && !held.repaint);
        let r = p.plan(0.2, 1, VIEW, 128, false);
        assert_eq!(r.job.as_ref().unwrap().target, 1);
        let moved = p.plan(0.3, 2, VIEW, 128, false);
        assert_eq!(moved.job.unwrap().target, 0);
        assert_eq!(moved.display, Some(0));
    }

    #[test]
    fn previews_respect_the_budget_and_floors() {
        let p = Progressive::new(1e-6, Budget::default());
        let (size, slices) = p.preview_level(VIEW, 128);
        assert!(slices >= MIN_PREVIEW_SLICES);
        assert!(size[0] >= (800.0 * MIN_PREVIEW_SCALE) as u32 - 1);
        let q = Quality {
            size,
            slices,
            full: false,
        };
        assert!(q.to_string().starts_with("preview "));
    }
}
