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
    /// Refinement waits for the GPU to finish its last chunk: the next frame is due when the
    /// GPU's fence reports it (the fence wakes the UI), or after a short while where nothing
    /// polls the GPU meanwhile (natively, callbacks run when a frame is submitted).
    pub waiting_for_gpu: bool,
    /// While waiting for the GPU: seconds until the last chunk is due on it, when the next
    /// frame may queue the next chunk whether its report came or not.
    pub wake_after: Option<f64>,
    /// A fenced chunk with more to come: seconds after the GPU starts it when it is due (the
    /// GPU's report that it is free for the chunk wakes the next frame then; see
    /// [`GpuReport::started`]).
    pub due_after_start: Option<f64>,
    /// The job's number (jobs are numbered from 1 as planned), which the GPU's fence reports
    /// back once the job is done ([`GpuReport::done`]).
    pub job_id: u64,
    /// Whether the job goes to the GPU in a submission of its own, ahead of the frame's, so
    /// that the GPU can time it (a fenced refinement chunk). Otherwise it goes with the frame's
    /// own commands: one submission a frame (a second one, even empty, doubled the frame's
    /// time on the CPU adapters of the browser tests), and its report is asked for at the next
    /// frame.
    pub own_submission: bool,
}

/// What the GPU has reported of the jobs the planner gave it ([`FramePlan::job_id`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GpuReport {
    /// The number of the last job finished (every job before it is finished too).
    pub done: u64,
    /// The last job finished whose own time is known: its number, and the seconds from the
    /// GPU's report that it was free for the job to its report of the job done.
    pub timed: Option<(u64, f64)>,
    /// The last job the GPU reported it was free to start, and the seconds since that report.
    pub started: Option<(u64, f64)>,
}

impl GpuReport {
    /// Jobs up to `done` finished, none timed.
    pub fn upto(done: u64) -> Self {
        Self {
            done,
            timed: None,
            started: None,
        }
    }
}

/// Frame-time budgets in seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// A preview frame (while dragging): 0.08 s by default, under the 0.1 s a drag's median
    /// frame may take on a CPU adapter with room for the frames that run over it.
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
            interactive: 0.08,
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
    /// When the view changed to it, or the pointer was last held on it, if later
    /// (seconds): when its refinement could begin.
    since: f64,
}

/// A job not yet measured.
#[derive(Clone, Debug)]
struct Pending {
    id: u64,
    /// When it was planned (seconds).
    then: f64,
    /// Pixel·slices.
    work: f64,
    /// A refinement chunk the next one waits for: measured by the GPU's time for it (or, where
    /// untimed, from its planning until its report is seen), where a preview is measured by
    /// the interval to the next frame.
    chunk: bool,
    /// When the model expects the GPU to be done with it (seconds): its report may come a
    /// good while later (0.1–0.16 s in SwiftShader's WebGPU), and the next chunk may queue
    /// behind it from then on.
    due: f64,
}

#[derive(Clone, Debug)]
struct Refine {
    key: u64,
    size: [u32; 2],
    total: u32,
    next: u32,
    /// When its first chunk was planned (seconds).
    started: f64,
    /// The seconds the model predicted for it, before [`Progressive::late`].
    predicted: f64,
    /// Whether the pointer was held during it: its time then says nothing of the model.
    interrupted: bool,
}

/// A refinement whose last chunk is on the GPU: when it is reported, the refinement's time is
/// known.
#[derive(Clone, Debug)]
struct Finishing {
    job: u64,
    started: f64,
    predicted: f64,
}

/// The planner; keep one per viewport.
#[derive(Clone, Debug)]
pub struct Progressive {
    budget: Budget,
    /// Seconds per weighted pixel·slice as frame intervals tell it (previews; chunks where the GPU
    /// does not time them): what sizes previews.
    cost: f64,
    /// Seconds per weighted pixel·slice as the GPU's timing of refinement chunks tells it, once it
    /// has timed one: what sizes chunks and the refined image. Frame intervals after a drag's
    /// previews count the frames' other work too: sizing chunks by them made them half as
    /// big as they could be, twice as many, each with a frame's overhead.
    chunk_cost: Option<f64>,
    /// Seconds every frame takes besides its volume work.
    overhead: f64,
    /// Recent frames with volume work: (weighted pixel·slices, seconds).
    samples: std::collections::VecDeque<(f64, f64)>,
    /// Seconds a timed chunk takes besides its work, from its planning to the frame that sees
    /// its report (the frame, the GPU's other work, the report's delay).
    per_chunk: f64,
    /// Since when the GPU has been behind the jobs planned (fenced refinement waits).
    behind_since: Option<f64>,
    /// Recent refinement chunks the GPU timed: (weighted pixel·slices, seconds).
    timed: std::collections::VecDeque<(f64, f64)>,
    /// Seconds every timed chunk took besides its work (fitted through `timed`): on a CPU
    /// adapter the GPU's report of a chunk comes a good while after the work is done.
    delay: f64,
    /// Jobs handed to the GPU and not yet measured, oldest first (a preview, fenced chunks).
    pending: std::collections::VecDeque<Pending>,
    /// When the report of the last fenced chunk was seen: a chunk queued behind another
    /// starts on the GPU no sooner.
    last_seen: f64,
    /// Jobs planned so far (the last job's number).
    jobs: u64,
    /// Fences off ([`Progressive::fenced`]), or the GPU never reported a job within
    /// [`FENCE_PATIENCE`]: chunks are not held back, and measured by frame intervals like
    /// previews.
    fence_silent: bool,
    shown: Option<Shown>,
    refine: Option<Refine>,
    /// The refinement whose last chunk is out, unless it was interrupted.
    finishing: Option<Finishing>,
    /// How much longer refinements took than the model predicted (an average ratio): the
    /// frames of a refinement do work the model does not see (a sky, ground and shafts of
    /// light drawn over the whole view on every frame, the browser's own work), so the
    /// resolution is chosen for the time refinements really take.
    late: f64,
    last_frame: Option<f64>,
    /// What a slice costs relative to a plain one ([`Progressive::weigh_slices`]): the work
    /// is counted in weighted pixel·slices, so the cost learnt stays one figure.
    weight: f64,
}

/// What a slice with shafts of light costs relative to a plain one: the slice pass then writes
/// and blends two targets, and the eye's shells come among the slices. Measured at about 2×
/// (`cloudsketch bench shafts`: a frame with shafts 2.0× one without on lavapipe; refinement
/// chunks in the page on SwiftShader about twice the plain ones).
pub const SHAFTS_SLICE_WEIGHT: f64 = 2.0;

/// The weight ([`Progressive::weigh_slices`]) of a slice of a view with shafts of light drawn
/// among its slices, or without.
pub fn slice_weight(shafts: bool) -> f64 {
    if shafts { SHAFTS_SLICE_WEIGHT } else { 1.0 }
}

/// How much longer than the model's time for a chunk the next one waits for its report before
/// it queues behind it anyway.
const DUE_MARGIN: f64 = 1.3;
/// Jobs kept for measuring at most (older ones are forgotten unmeasured).
const PENDING_KEPT: usize = 8;

/// Fewest slices a preview uses.
const MIN_PREVIEW_SLICES: u32 = 16;
/// Smallest preview resolution scale.
const MIN_PREVIEW_SCALE: f64 = 0.15;
/// Smallest resolution scale of the refined (full-quality) image.
pub const MIN_REFINE_SCALE: f64 = 0.25;
/// How far [`Progressive::late`] may go: refinements taking half to four times the model's
/// time.
const LATE_RANGE: (f64, f64) = (0.5, 4.0);
/// Frames the overhead is fitted over.
const SAMPLES: usize = 16;
/// Seconds a refinement chunk may go unreported by the GPU's fence before the planner stops
/// waiting for fences (a chunk is sized to a quarter second).
pub const FENCE_PATIENCE: f64 = 5.0;

impl Progressive {
    /// A planner starting from a guessed cost in seconds per pixel·slice.
    pub fn new(initial_cost: f64, budget: Budget) -> Self {
        Self {
            budget,
            cost: initial_cost.max(1e-12),
            chunk_cost: None,
            overhead: 0.0,
            samples: std::collections::VecDeque::new(),
            timed: std::collections::VecDeque::new(),
            delay: 0.0,
            behind_since: None,
            per_chunk: 0.0,
            pending: std::collections::VecDeque::new(),
            last_seen: f64::NEG_INFINITY,
            jobs: 0,
            fence_silent: false,
            shown: None,
            refine: None,
            finishing: None,
            late: 1.0,
            last_frame: None,
            weight: 1.0,
        }
    }

    /// Whether a refinement chunk waits for the GPU's report of the one before it (see
    /// [`Progressive::plan`]); without, chunks follow frame after frame.
    pub fn fenced(mut self, on: bool) -> Self {
        self.fence_silent = !on;
        self
    }

    /// Tells the planner what each slice of the view costs relative to a plain slice
    /// ([`SHAFTS_SLICE_WEIGHT`] with shafts of light, else 1), before [`Progressive::plan`].
    /// Turning the shafts on then plans the next preview and refinement for their cost at
    /// once, instead of the first refinement overrunning its budget while the cost is
    /// relearnt (and turning them off gives the plain resolution back at once).
    pub fn weigh_slices(&mut self, weight: f64) {
        if weight.is_finite() && weight > 0.0 {
            self.weight = weight;
        }
    }

    /// Current cost estimate in seconds per weighted pixel·slice of refinement's work (the
    /// GPU's timing of chunks where it has timed one, else frame intervals): a plain slice's
    /// cost; a slice of weight `w` ([`slice_weight`]) costs `w` times it.
    pub fn cost(&self) -> f64 {
        match self.chunk_cost {
            // Chunks no longer timed (the fence went silent) are measured as previews are.
            Some(cost) if !self.fence_silent => cost,
            _ => self.cost,
        }
    }

    /// How much longer refinements have taken than the model predicted (see
    /// `Progressive::late`'s field).
    pub fn late(&self) -> f64 {
        self.late
    }

    /// Volume jobs planned so far (previews and refinement chunks).
    pub fn jobs(&self) -> u64 {
        self.jobs
    }

    /// Interval of the last measured frame that carried volume work, in seconds.
    pub fn last_frame_seconds(&self) -> Option<f64> {
        self.last_frame
    }

    /// Forgets the shown image (e.g. the GPU targets were lost).
    pub fn reset(&mut self) {
        self.shown = None;
        self.refine = None;
        self.finishing = None;
        self.pending.clear();
    }

    /// Plans the frame at time `now` (seconds) for a view identified by `key` in a viewport of
    /// `viewport` pixels whose full quality is `full_slices`. While `interacting` (pointer held)
    /// no refinement starts, so dragging stays responsive. `gpu` is what the GPU has reported
    /// of the jobs (see [`FramePlan::job_id`]): with fences on, a refinement chunk is planned
    /// only once every job before it is done, so a drag that starts during refinement waits
    /// for one chunk at most (a browser otherwise lets two or three queue up).
    pub fn plan(
        &mut self,
        now: f64,
        key: u64,
        viewport: [u32; 2],
        full_slices: u32,
        interacting: bool,
        gpu: GpuReport,
    ) -> FramePlan {
        self.measure(now, gpu);
        // The GPU has started a chunk: it is due once the chunk's work is done.
        if let Some((id, ago)) = gpu.started {
            let cost = self.cost();
            if let Some(p) = self.pending.iter_mut().find(|p| p.id == id && p.chunk) {
                p.due = p.due.min(now - ago + DUE_MARGIN * cost * p.work);
            }
        }
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
                since: now,
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
                false,
            );
        }
        let Some(shown) = self.shown.clone() else {
            unreachable!("set above")
        };
        let chunk_on_gpu = self.pending.iter().any(|p| p.chunk);
        if interacting && let Some(r) = &mut self.refine {
            r.interrupted = true;
        }
        if interacting && let Some(s) = &mut self.shown {
            s.since = now;
        }
        if shown.quality.full || interacting {
            return FramePlan {
                job: None,
                display: Some(shown.target),
                shown: Some(shown.quality),
                refining: None,
                repaint: false,
                // The last chunk is measured when the GPU reports it, not at the next input.
                waiting_for_gpu: chunk_on_gpu,
                wake_after: None,
                due_after_start: None,
                job_id: 0,
                own_submission: false,
            };
        }
        // The GPU has yet to report the last job (a chunk, or the preview before the first):
        // a chunk now would queue behind it. Unless that job is a chunk the GPU should be done
        // with by now: its report is on its way, and waiting for it would leave the GPU idle
        // (half of a chunk's time in SwiftShader's WebGPU). The chunk's start was reported
        // once all work before it was done, so an earlier chunk still unreported is done too
        // (one at most: should the model's times run short, chunks never pile up). Past the
        // fence's patience, stop waiting for reports.
        let outstanding = self.jobs.saturating_sub(gpu.done);
        let last_due = self
            .pending
            .back()
            .filter(|p| p.chunk && p.id == self.jobs)
            .map(|p| p.due);
        let done_by_now = outstanding <= 2 && last_due.is_some_and(|due| now >= due);
        let behind = !self.fence_silent && outstanding > 0 && !done_by_now;
        if behind {
            let since = *self.behind_since.get_or_insert(now);
            if now - since > FENCE_PATIENCE {
                self.fence_silent = true;
            }
        } else {
            self.behind_since = None;
        }
        if behind && !self.fence_silent {
            // The last job is still on the GPU: show what there is and look again (when the
            // fence reports it, or when the chunk is due).
            return FramePlan {
                job: None,
                display: Some(shown.target),
                shown: Some(shown.quality),
                refining: self
                    .refine
                    .as_ref()
                    .filter(|r| r.key == key)
                    .map(|r| r.next as f32 / r.total as f32),
                repaint: false,
                waiting_for_gpu: true,
                wake_after: last_due
                    .filter(|&due| due > now && due.is_finite())
                    .map(|due| due - now),
                due_after_start: None,
                job_id: 0,
                own_submission: false,
            };
        }
        // Full quality is due within the budget of the change, the frames before the first
        // chunk included (the one that turns the ground or the shafts on draws the view
        // behind the cloud: a third of a second on a CPU adapter).
        let spent = (now - shown.since).max(0.0);
        let within = (self.budget.refine_total - spent).max(0.5 * self.budget.refine_total);
        let (size, predicted) = self.refine_plan_within(viewport, full_slices, within);
        let chunk_seconds = self.chunk_seconds();
        let cost = self.cost();
        let refine = match &mut self.refine {
            Some(r) if r.key == key => r,
            slot => slot.insert(Refine {
                key,
                size,
                total: full_slices,
                next: 0,
                started: now,
                predicted,
                interrupted: false,
            }),
        };
        let pixels = refine.size[0] as f64 * refine.size[1] as f64;
        // Chunks the GPU times alternate in size, so that their times tell the work's part
        // from the fixed delay of the GPU's reports.
        let vary = if !self.fence_silent && !self.timed.is_empty() && self.jobs % 2 == 1 {
            0.7
        } else {
            1.0
        };
        let per_chunk = (vary * chunk_seconds / (cost * pixels * self.weight))
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
                since: shown.since,
            });
            self.finishing = self
                .refine
                .take()
                .filter(|r| !r.interrupted)
                .map(|r| Finishing {
                    job: self.jobs + 1,
                    started: r.started,
                    predicted: r.predicted,
                });
            self.submit(now, job, Some(1), None, true)
        } else {
            self.submit(now, job, Some(shown.target), Some(progress), true)
        }
    }

    fn submit(
        &mut self,
        now: f64,
        job: JobPlan,
        display: Option<usize>,
        refining: Option<f32>,
        chunk: bool,
    ) -> FramePlan {
        let work = job.size[0] as f64
            * job.size[1] as f64
            * (job.range.end - job.range.start) as f64
            * self.weight;
        self.jobs += 1;
        // A chunk is followed by a frame only once the GPU reports it done: a frame drawn
        // meanwhile would only queue more work behind it.
        let fenced = chunk && !self.fence_silent;
        if self.pending.len() >= PENDING_KEPT {
            self.pending.pop_front();
        }
        // Due once the GPU has started it and done its work, with a margin (a chunk queued
        // behind one still at work would hold a drag starting then for both).
        let seconds = DUE_MARGIN * self.cost() * work;
        self.pending.push_back(Pending {
            id: self.jobs,
            then: now,
            work,
            chunk: fenced,
            due: f64::INFINITY,
        });
        FramePlan {
            job: Some(job),
            display,
            shown: self.shown.as_ref().map(|s| s.quality),
            refining,
            repaint: !fenced,
            waiting_for_gpu: fenced,
            wake_after: None,
            // More chunks to come: the next when this one is due, if its report is late.
            due_after_start: (fenced && refining.is_some()).then_some(seconds),
            job_id: self.jobs,
            own_submission: fenced,
        }
    }

    /// Learns the cost and the overhead from the time the last job took: a preview's is the
    /// interval to the next frame (while dragging, frames queue behind the GPU); a fenced
    /// refinement chunk's is the GPU's own time for it (`gpu.timed`), less the reports' fixed
    /// delay, or where untimed the time until its report is seen. The overhead is the
    /// intercept of a line fitted through recent frames of different sizes; the cost is what a
    /// frame took beyond it.
    fn measure(&mut self, now: f64, gpu: GpuReport) {
        let gpu_done = gpu.done;
        let ready = |p: &Pending| !p.chunk || gpu_done >= p.id || now - p.then > FENCE_PATIENCE;
        // A chunk queued behind another started on the GPU once that one was seen done
        // (before this frame: two reported now were not both seen now).
        let seen = self.last_seen;
        let mut reported = false;
        while let Some(k) = self.pending.iter().position(ready) {
            if let Some(pending) = self.pending.remove(k) {
                reported |= pending.chunk && gpu_done >= pending.id;
                self.measure_job(now, gpu, pending, seen);
            }
        }
        if reported {
            self.last_seen = now;
        }
    }

    /// [`Progressive::measure`] of one job; `seen`: when the last chunk before this frame's
    /// was seen done.
    fn measure_job(&mut self, now: f64, gpu: GpuReport, pending: Pending, seen: f64) {
        let gpu_done = gpu.done;
        if let Some(f) = self.finishing.take_if(|f| f.job == pending.id)
            && f.predicted > 0.0
        {
            // The refinement is done: how its time compares with the model's.
            let ratio = ((now - f.started) / f.predicted).clamp(LATE_RANGE.0, LATE_RANGE.1);
            self.late = (0.5 * self.late + 0.5 * ratio).clamp(LATE_RANGE.0, LATE_RANGE.1);
        }
        let Pending { then, work, .. } = pending;
        if pending.chunk
            && let Some((id, seconds)) = gpu.timed
            && id == pending.id
        {
            // The GPU's own time for the chunk, between its two reports: no frame's other work
            // in it, so it teaches the cost (and the reports' delay), not the overhead's line.
            if seconds > 0.0 && work > 0.0 {
                self.last_frame = Some(seconds);
                if self.timed.len() == SAMPLES {
                    self.timed.pop_front();
                }
                self.timed.push_back((work, seconds));
                // The work's part: the line's slope once chunks of different sizes tell it from
                // the fixed delay (chunks alternate in size for that), else the chunk's seconds
                // less the delay known so far.
                let (slope, intercept) = fit_line(&self.timed);
                if let Some(intercept) = intercept {
                    self.delay = 0.5 * self.delay + 0.5 * intercept;
                }
                let cost = self.cost();
                let sample = slope
                    .unwrap_or(((seconds - self.delay).max(0.25 * seconds)) / work)
                    .min(cost * 20.0);
                let w = if sample > cost { 0.6 } else { 0.25 };
                let cost = cost * (1.0 - w) + sample * w;
                self.chunk_cost = Some(cost);
                // A preview's frame costs at least its work.
                self.cost = self.cost.max(cost);
                // What a chunk costs in time besides its work, from its planning until the
                // frame that saw its report: what refining at a resolution must count per chunk.
                let beyond = (now - then.max(seen) - cost * work).max(0.0);
                self.per_chunk = if self.per_chunk > 0.0 {
                    0.7 * self.per_chunk + 0.3 * beyond
                } else {
                    beyond
                };
            }
            return;
        }
        if pending.chunk && gpu.timed.is_some() && gpu_done >= pending.id {
            // Reported with a later chunk, which the GPU timed: its own time is not known.
            return;
        }
        let dt = now - if pending.chunk { then.max(seen) } else { then };
        if pending.chunk && gpu_done < pending.id {
            // No word from the GPU: stop waiting for it from now on.
            self.fence_silent = true;
            return;
        }
        if pending.chunk && dt > FENCE_PATIENCE {
            // Reported, but seen only now (no frame came meanwhile): not a measure of it.
            return;
        }
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
        // Rise fast (stay responsive), fall slowly (don't trust one quick frame), and never
        // below the work's cost the GPU timed: a quick frame says little while the GPU is not
        // behind (frames then come at the display's pace).
        let w = if sample > self.cost { 0.6 } else { 0.25 };
        let timed = self.chunk_cost.filter(|_| !self.fence_silent);
        self.cost = (self.cost * (1.0 - w) + sample * w).max(timed.unwrap_or(0.0));
    }

    /// Least squares of seconds on work over the recent frames, when their sizes differ enough
    /// to tell a fixed part from a proportional one (see also `fit_line`).
    fn fit_overhead(&mut self) {
        if self.samples.len() < 4 {
            return;
        }
        let Some((_, intercept)) = least_squares(&self.samples, 0.3) else {
            return;
        };
        // Never more than half the quickest recent frame: a wrong fit must not make the cost
        // look small (the next chunk would then take seconds).
        let quickest = self
            .samples
            .iter()
            .map(|&(_, d)| d)
            .fold(f64::MAX, f64::min);
        let intercept = intercept.clamp(0.0, 0.5 * quickest);
        self.overhead = 0.5 * self.overhead + 0.5 * intercept;
    }

    /// Seconds of volume work per refinement chunk: the chunk budget less the frame's
    /// overhead, so a refining frame stays near the budget.
    fn chunk_seconds(&self) -> f64 {
        if self.fence_silent {
            (self.budget.refine - self.overhead).max(0.5 * self.budget.refine)
        } else {
            // Fenced: a drag starting now waits for this chunk and the frame queued before it.
            (self.budget.refine - 2.0 * self.overhead)
                .clamp(0.4 * self.budget.refine, 0.6 * self.budget.refine)
        }
    }

    /// Resolution of the refined image: the viewport's, or less where the adapter could not
    /// refine it within the budget's total, counting each chunk frame's overhead.
    fn refine_size(&self, viewport: [u32; 2], full_slices: u32) -> [u32; 2] {
        self.refine_plan(viewport, full_slices).0
    }

    /// [`Progressive::refine_size`], and the seconds the model predicts for it before
    /// [`Progressive::late`] (which the choice counts).
    fn refine_plan(&self, viewport: [u32; 2], full_slices: u32) -> ([u32; 2], f64) {
        self.refine_plan_within(viewport, full_slices, self.budget.refine_total)
    }

    /// [`Progressive::refine_plan`] within `budget` seconds.
    fn refine_plan_within(
        &self,
        viewport: [u32; 2],
        full_slices: u32,
        budget: f64,
    ) -> ([u32; 2], f64) {
        let seconds = |scale: f64| {
            let work = self.cost()
                * (viewport[0] as f64 * scale).round().max(1.0)
                * (viewport[1] as f64 * scale).round().max(1.0)
                * full_slices as f64
                * self.weight;
            // Each chunk also costs a frame's overhead; a timed one also waits for its report.
            let fixed = if self.fence_silent {
                self.overhead
            } else {
                self.overhead.max(self.per_chunk)
            };
            work + (work / self.chunk_seconds()).ceil() * fixed
        };
        let mut scale: f64 = 1.0;
        while scale > MIN_REFINE_SCALE && self.late * seconds(scale) > budget {
            scale *= 0.95;
        }
        let scale = scale.max(MIN_REFINE_SCALE);
        let size = viewport.map(|v| ((v as f64 * scale).round() as u32).max(1));
        (size, seconds(scale))
    }

    fn preview_level(&self, viewport: [u32; 2], full_slices: u32) -> ([u32; 2], u32) {
        let pixels = viewport[0] as f64 * viewport[1] as f64;
        let predicted = self.cost * pixels * full_slices as f64 * self.weight;
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

/// The line `seconds = slope · work + intercept` through `samples` (work, seconds) by least
/// squares, where their work differs enough to tell the two apart and both come out positive:
/// (slope, intercept); the slope alone where the intercept comes out negative (taken as 0).
fn fit_line(samples: &std::collections::VecDeque<(f64, f64)>) -> (Option<f64>, Option<f64>) {
    if samples.len() < 3 {
        return (None, None);
    }
    let Some((slope, intercept)) = least_squares(samples, 0.15) else {
        return (None, None);
    };
    if intercept < 0.0 {
        // Through the origin instead.
        let (ww, ws) = samples
            .iter()
            .fold((0.0, 0.0), |(a, b), &(w, s)| (a + w * w, b + w * s));
        return ((ww > 0.0).then(|| ws / ww), Some(0.0));
    }
    (Some(slope), Some(intercept))
}

/// The least-squares line of seconds on work through `samples` (work, seconds): (slope,
/// intercept), where the work's spread (standard deviation) is at least `spread` of its mean
/// and seconds grow with it; else none.
fn least_squares(
    samples: &std::collections::VecDeque<(f64, f64)>,
    spread: f64,
) -> Option<(f64, f64)> {
    let n = samples.len() as f64;
    if n == 0.0 {
        return None;
    }
    let (mw, ms) = samples
        .iter()
        .fold((0.0, 0.0), |(a, b), &(w, s)| (a + w / n, b + s / n));
    let (var, cov) = samples.iter().fold((0.0, 0.0), |(v, c), &(w, s)| {
        (v + (w - mw) * (w - mw), c + (w - mw) * (s - ms))
    });
    if var < (spread * mw).powi(2) * n || cov <= 0.0 {
        return None;
    }
    let slope = cov / var;
    Some((slope, ms - slope * mw))
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
        // Each frame's work is done when the next frame starts.
        let mut done = 0;
        for frame in 1..1000 {
            let plan = p.plan(*t, key, view, 128, false, GpuReport::upto(done));
            done = done.max(plan.job_id);
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
        // Frames measured by their intervals (as natively, and as before fences).
        let mut p = Progressive::new(true_cost / 3.0, Budget::default()).fenced(false);
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
        let plan = p.plan(0.0, 1, VIEW, 128, false, GpuReport::upto(u64::MAX));
        assert_eq!(
            plan.shown,
            Some(Quality {
                size: VIEW,
                slices: 128,
                full: true
            })
        );
        let plan = p.plan(0.02, 1, VIEW, 128, false, GpuReport::upto(u64::MAX));
        assert!(plan.job.is_none() && !plan.repaint);
    }

    #[test]
    fn chunks_cover_every_slice_exactly_once() {
        let mut p = Progressive::new(1e-7, Budget::default());
        let mut t = 0.0;
        p.plan(t, 9, VIEW, 100, false, GpuReport::upto(u64::MAX));
        let mut covered = Vec::new();
        loop {
            t += 0.1;
            let plan = p.plan(t, 9, VIEW, 100, false, GpuReport::upto(u64::MAX));
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
        let a = p.plan(0.0, 1, VIEW, 128, false, GpuReport::upto(u64::MAX));
        assert_eq!(a.job.as_ref().unwrap().target, 0);
        assert!(!a.shown.unwrap().full);
        let held = p.plan(0.1, 1, VIEW, 128, true, GpuReport::upto(u64::MAX));
        assert!(held.job.is_none() && !held.repaint);
        let r = p.plan(0.2, 1, VIEW, 128, false, GpuReport::upto(u64::MAX));
        assert_eq!(r.job.as_ref().unwrap().target, 1);
        let moved = p.plan(0.3, 2, VIEW, 128, false, GpuReport::upto(u64::MAX));
        assert_eq!(moved.job.unwrap().target, 0);
        assert_eq!(moved.display, Some(0));
    }

    #[test]
    fn a_chunk_waits_until_the_gpu_has_done_the_one_before() {
        let mut p = Progressive::new(1e-8, Budget::default());
        let preview = p.plan(0.0, 1, VIEW, 128, false, GpuReport::upto(0));
        let first = p.plan(0.1, 1, VIEW, 128, false, GpuReport::upto(preview.job_id));
        let range = first.job.as_ref().unwrap().range.clone();
        assert!(
            range.end < 128,
            "the refinement takes several chunks: {range:?}"
        );
        // The chunk goes to the GPU on its own, to be timed; the preview with its frame.
        assert!(first.own_submission && !preview.own_submission);
        // The GPU is still on that chunk: nothing more is queued, the image shown stays, and
        // the fence is to wake the next frame.
        for t in [0.2, 0.3, 0.4] {
            let waiting = p.plan(t, 1, VIEW, 128, false, GpuReport::upto(preview.job_id));
            assert!(waiting.job.is_none() && waiting.waiting_for_gpu);
            assert_eq!(waiting.display, first.display);
            assert_eq!(waiting.refining, first.refining);
        }
        // Done: the next chunk follows on from the first.
        let next = p.plan(0.5, 1, VIEW, 128, false, GpuReport::upto(first.job_id));
        assert_eq!(next.job.as_ref().unwrap().range.start, range.end);
        // A view change is drawn at once, whatever the GPU is doing.
        let moved = p.plan(0.6, 2, VIEW, 128, false, GpuReport::upto(first.job_id));
        assert_eq!(moved.job.unwrap().target, 0);
    }

    #[test]
    fn a_silent_fence_holds_refinement_back_no_longer_than_its_patience() {
        // Six seconds of refinement: many chunks.
        let mut p = Progressive::new(1e-7, Budget::default());
        p.plan(0.0, 1, VIEW, 128, false, GpuReport::upto(0));
        // The GPU never reports anything done: not even the preview, so no chunk follows it.
        assert!(
            p.plan(0.1, 1, VIEW, 128, false, GpuReport::upto(0))
                .waiting_for_gpu
        );
        let t = 0.1 + 0.5 * FENCE_PATIENCE;
        assert!(
            p.plan(t, 1, VIEW, 128, false, GpuReport::upto(0))
                .waiting_for_gpu
        );
        let mut t = 0.2 + FENCE_PATIENCE;
        // From then on chunks follow each other as frames come, as before fences.
        for _ in 0..3 {
            let plan = p.plan(t, 1, VIEW, 128, false, GpuReport::upto(0));
            assert!(
                plan.job.is_some() && !plan.waiting_for_gpu && !plan.own_submission,
                "{plan:?}"
            );
            t += 0.1;
        }
    }

    /// A browser over a CPU adapter: the page's frames run ahead of the GPU (up to `ahead`
    /// frames wait on it, else frames come every 1/60 s), the GPU runs the frames in order,
    /// each taking `overhead` plus its volume work at `cost`, and its fence reports a job done
    /// once the GPU has finished it (waking the page if refinement waits for it).
    struct Browser {
        cost: f64,
        overhead: f64,
        ahead: usize,
        /// Fences off: the planner is told every job is done (as before fences).
        unfenced: bool,
        /// Seconds from a job's end on the GPU to its report, which are also in the GPU's
        /// time of the job (as measured in SwiftShader's WebGPU: about 0.16 s at 1920×1080).
        delay: f64,
        /// The part of a chunk's time the GPU's timing of it sees (1: all of it). On a CPU
        /// adapter the frame's passes over the whole view (a sky, the ground, shafts of light
        /// around the cloud) share the cores with the chunk while it runs, and its timing
        /// holds what it did, not what slowed it.
        seen: f64,
        /// What a slice costs relative to a plain one (2 with shafts of light).
        weight: f64,
        /// The GPU reports when it starts a job (as the fence's report that the work before
        /// the job is done): off, as before the planner used it.
        starts: bool,
        t: f64,
        gpu_free: f64,
        /// GPU end times of the frames not yet finished, oldest first.
        queued: std::collections::VecDeque<f64>,
        /// (end, job, the job's own GPU seconds) of every job.
        jobs: Vec<(f64, u64, f64)>,
    }

    impl Browser {
        fn new(cost: f64, overhead: f64, unfenced: bool, delay: f64) -> Self {
            Self {
                cost,
                overhead,
                ahead: 3,
                unfenced,
                delay,
                seen: 1.0,
                weight: 1.0,
                starts: true,
                t: 0.0,
                gpu_free: 0.0,
                queued: Default::default(),
                jobs: Vec::new(),
            }
        }

        /// Frames of view `key` until full quality is shown: the longest a drag starting right
        /// after one of them would wait for the GPU, and the seconds to full quality.
        fn refine(&mut self, p: &mut Progressive, key: u64, view: [u32; 2]) -> (f64, f64) {
            let (t0, mut stall) = (self.t, 0.0f64);
            for _ in 0..10_000 {
                let t = self.t;
                let report = if self.unfenced {
                    GpuReport::upto(u64::MAX)
                } else {
                    let reported = self.jobs.iter().filter(|(end, ..)| end + self.delay <= t);
                    let last = reported.max_by(|a, b| a.1.cmp(&b.1));
                    // The GPU's report that it is free for a job comes as it starts it.
                    let started = self
                        .jobs
                        .iter()
                        .filter(|&&(end, _, seconds)| end - seconds <= t)
                        .max_by(|a, b| a.1.cmp(&b.1))
                        .map(|&(end, id, seconds)| (id, t - (end - seconds)))
                        .filter(|_| self.starts);
                    GpuReport {
                        done: last.map_or(0, |j| j.1),
                        timed: last.map(|&(_, id, seconds)| (id, self.seen * seconds + self.delay)),
                        started,
                    }
                };
                let plan = p.plan(t, key, view, 128, false, report);
                if plan.shown.is_some_and(|q| q.full) && plan.job.is_none() && !plan.repaint {
                    return (stall, t - t0);
                }
                let work = plan.job.as_ref().map_or(0.0, |j| {
                    j.size[0] as f64 * j.size[1] as f64 * (j.range.end - j.range.start) as f64
                });
                let work = work * self.weight;
                let end = self.gpu_free.max(t) + self.overhead + work * self.cost;
                // A drag starting right after this frame waits until the GPU is through.
                stall = stall.max(end - t);
                self.gpu_free = end;
                if plan.job.is_some() {
                    self.jobs.push((end, plan.job_id, work * self.cost));
                }
                self.queued.push_back(end);
                let mut next = t + 1.0 / 60.0;
                if plan.waiting_for_gpu {
                    // No frame until the fence wakes the page: the last job's report (an
                    // earlier job's wakes nothing).
                    let report = self
                        .jobs
                        .last()
                        .map(|&(end, ..)| end + self.delay)
                        .filter(|&at| at > t)
                        .unwrap_or(next);
                    // Or when the chunk is due: after its start, or, once started, from now.
                    let started = |id: u64| {
                        self.jobs
                            .iter()
                            .find(|j| j.1 == id)
                            .map(|&(end, _, seconds)| end - seconds)
                    };
                    let due = match (plan.due_after_start, plan.wake_after) {
                        (Some(after), _) => started(plan.job_id).map_or(report, |s| s + after),
                        (None, Some(w)) => t + w,
                        (None, None) => report,
                    };
                    next = next.max(report.min(due));
                }
                self.queued.retain(|&e| e > next);
                while self.queued.len() >= self.ahead {
                    next = self.queued.pop_front().unwrap_or(next);
                    self.queued.retain(|&e| e > next);
                }
                self.t = next;
            }
            panic!("never reached full quality");
        }
    }

    #[test]
    fn a_drag_during_refinement_waits_for_one_chunk_not_the_frames_queued_ahead() {
        // SwiftShader at 1280×800 in the headless browser: the cloud's box 800×600 px, 6 s at
        // full resolution in one go, 67 ms of compositing in every frame; the GPU's reports
        // come at once, or 0.16 s late (as SwiftShader's WebGPU at 1920×1080).
        let cost = 6.0 / (800.0 * 600.0 * 128.0);
        let run = |unfenced: bool, delay: f64| {
            let mut b = Browser::new(cost, 0.067, unfenced, delay);
            let mut p = Progressive::new(cost / 3.0, Budget::default()).fenced(!unfenced);
            for key in 1..4 {
                b.refine(&mut p, key, VIEW);
            }
            let (stall, seconds) = b.refine(&mut p, 9, VIEW);
            (stall, seconds, p.cost() / cost, p.refine_size(VIEW, 128))
        };
        let pace = |seconds: f64, size: [u32; 2]| size[0] as f64 * size[1] as f64 / seconds;
        let (stall_before, seconds_before, _, size_before) = run(true, 0.0);
        // Before fences, frames of a quarter second each queued up behind each other.
        assert!(stall_before > 0.45, "unfenced: {stall_before:.2} s");
        // (With the delay counted as work, chunks shrink until each is mostly delay: 0.1 of
        // the pace.)
        for (delay, kept) in [(0.0, 0.6), (0.16, 0.3)] {
            let (stall, seconds, learnt, size) = run(false, delay);
            assert!(
                stall < 0.3,
                "fenced, reports {delay} s late: {stall:.2} s (unfenced {stall_before:.2} s)"
            );
            // The cost is still learnt (chunks timed by the GPU, their reports' delay told
            // apart, not frame intervals, which are short while no chunk queues), and
            // refinement keeps much of its pace: a chunk waits for the report of the one before.
            assert!(
                (learnt - 1.0).abs() < 0.3,
                "reports {delay} s late: learnt {learnt:.2} of the true cost"
            );
            assert!(
                pace(seconds, size) > kept * pace(seconds_before, size_before)
                    && size[0] as f64 >= 0.8 * size_before[0] as f64
                    && seconds < 2.5,
                "fenced, reports {delay} s late: {seconds:.2} s at {size:?}, unfenced \
                 {seconds_before:.2} s at {size_before:?}"
            );
        }
    }

    #[test]
    fn a_chunk_follows_the_one_before_once_it_is_due_not_when_its_late_report_comes() {
        // SwiftShader at 1280×800 as above, its reports 0.16 s late: the GPU would wait for
        // each report; queued once the chunk before is due, the next keeps it busy.
        let cost = 6.0 / (800.0 * 600.0 * 128.0);
        let run = |starts: bool| {
            let mut b = Browser::new(cost, 0.067, false, 0.16);
            b.starts = starts;
            let mut p = Progressive::new(cost / 3.0, Budget::default());
            for key in 1..4 {
                b.refine(&mut p, key, VIEW);
            }
            let (stall, seconds) = b.refine(&mut p, 9, VIEW);
            let size = p.refine_size(VIEW, 128);
            (stall, seconds, size[0] as f64 * size[1] as f64)
        };
        let (stall, seconds, pixels) = run(true);
        // Baseline: a planner that waits for every report.
        let (stall_before, seconds_before, pixels_before) = run(false);
        let pace = pixels / seconds;
        let pace_before = pixels_before / seconds_before;
        assert!(
            pace > 1.25 * pace_before,
            "{pixels} px in {seconds:.2} s, waiting for reports {pixels_before} px in \
             {seconds_before:.2} s"
        );
        // A drag starting meanwhile still waits for about one chunk.
        assert!(
            stall < 0.3 && stall < stall_before + 0.1,
            "{stall:.2} s, waiting for reports {stall_before:.2} s"
        );
    }

    #[test]
    fn time_spent_before_the_first_chunk_is_taken_from_the_refinements_budget() {
        // A preview frame that took 0.6 s (the view behind the cloud drawn with it): the
        // refinement after it is planned for what is left of the budget.
        let refined = |preview_seconds: f64| {
            let mut p = Progressive::new(2e-8, Budget::default());
            let preview = p.plan(0.0, 1, VIEW, 128, false, GpuReport::upto(0));
            // The preview's frame took its budget either way (the cost learnt is the same); its
            // report came at once, or after `preview_seconds` (the view behind the cloud).
            p.plan(0.08, 1, VIEW, 128, false, GpuReport::upto(0));
            let first = p.plan(
                preview_seconds,
                1,
                VIEW,
                128,
                false,
                GpuReport::upto(preview.job_id),
            );
            first.job.map(|j| j.size).unwrap_or_default()
        };
        let (quick, slow) = (refined(0.09), refined(0.6));
        assert!(
            slow[0] < quick[0],
            "{slow:?} after a slow preview, {quick:?} after a quick one"
        );
        // The pointer held still for a second before its release: the refinement could not
        // begin before, and keeps its whole budget.
        let mut p = Progressive::new(2e-8, Budget::default());
        let preview = p.plan(0.0, 1, VIEW, 128, true, GpuReport::upto(0));
        for k in 1..50 {
            let t = k as f64 * 0.02;
            p.plan(t, 1, VIEW, 128, true, GpuReport::upto(preview.job_id));
        }
        let first = p.plan(1.02, 1, VIEW, 128, false, GpuReport::upto(preview.job_id));
        assert_eq!(first.job.map(|j| j.size), Some(quick));
    }

    #[test]
    fn refinement_keeps_to_its_budget_with_work_the_model_does_not_see() {
        // SwiftShader at 1280×800 with a sky, the ground and shafts of light: every chunk
        // also takes time its GPU timing does not show (the frame's passes over the whole view
        // share the CPU with it), half its time here.
        let cost = 6.0 / (800.0 * 600.0 * 128.0);
        let mut b = Browser::new(cost, 0.067, false, 0.0);
        b.seen = 0.5;
        // No chunk queued early (the GPU's starts unreported): the lateness alone keeps it.
        b.starts = false;
        let mut p = Progressive::new(cost / 3.0, Budget::default());
        let mut last = 0.0;
        for key in 1..6 {
            last = b.refine(&mut p, key, VIEW).1;
        }
        // Refinements learn how late they come: the last one keeps to the budget (less the
        // preview before it), where the model alone took 2.0 s.
        assert!(
            last <= Budget::default().refine_total * 1.15,
            "refined in {last:.2} s, late {:.2}",
            p.late
        );
        assert!(p.late > 1.2, "late {:.2}", p.late);
    }

    #[test]
    fn shafts_turned_on_are_planned_for_from_their_first_refinement() {
        // SwiftShader at 1280×800, as above; then the shafts of light go on, and every slice
        // costs twice as much (two targets written and blended, the shells among the slices).
        let cost = 6.0 / (800.0 * 600.0 * 128.0);
        let run = |told: f64| {
            let mut b = Browser::new(cost, 0.067, false, 0.0);
            let mut p = Progressive::new(cost / 3.0, Budget::default());
            for key in 1..6 {
                b.refine(&mut p, key, VIEW);
            }
            b.weight = 2.0;
            p.weigh_slices(told);
            let (_, seconds) = b.refine(&mut p, 9, VIEW);
            (seconds, p.refine_size(VIEW, 128))
        };
        let (told, size) = run(SHAFTS_SLICE_WEIGHT);
        // Baseline: a planner not told, which relearns the cost during the refinement.
        let (untold, untold_size) = run(1.0);
        let budget = Budget::default().refine_total;
        assert!(
            told <= budget * 1.15 && untold > 1.15 * told,
            "with shafts: {told:.2} s at {size:?} told, {untold:.2} s untold ({untold_size:?})"
        );
        // Turned off again: the plain resolution at once.
        let mut b = Browser::new(cost, 0.067, false, 0.0);
        let mut p = Progressive::new(cost / 3.0, Budget::default());
        for key in 1..6 {
            b.refine(&mut p, key, VIEW);
        }
        let plain = p.refine_size(VIEW, 128);
        p.weigh_slices(SHAFTS_SLICE_WEIGHT);
        let shafts = p.refine_size(VIEW, 128);
        p.weigh_slices(1.0);
        assert!(
            shafts[0] < plain[0] && p.refine_size(VIEW, 128) == plain,
            "{plain:?} {shafts:?}"
        );
    }

    #[test]
    fn chunks_no_longer_timed_are_sized_by_the_frames_again() {
        // The GPU timed chunks, then its reports stopped (the fence went silent) and the work
        // became three times dearer: the cost follows the frames, not the last timing.
        let cost = 6.0 / (800.0 * 600.0 * 128.0);
        let mut b = Browser::new(cost, 0.05, false, 0.0);
        let mut p = Progressive::new(cost, Budget::default());
        for key in 1..4 {
            b.refine(&mut p, key, VIEW);
        }
        assert!(p.chunk_cost.is_some());
        p.fence_silent = true;
        b.unfenced = true;
        b.cost *= 3.0;
        for key in 4..8 {
            b.refine(&mut p, key, VIEW);
        }
        let learnt = p.cost() / b.cost;
        assert!(
            (learnt - 1.0).abs() < 0.5,
            "learnt {learnt:.2} of the true cost"
        );
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
