//! The path tracer's batched kernel: one pass's camera samples in a batch of [`LANES`] lanes,
//! stage by stage (see the module above for the stages and why they give the scalar image).

use spectrace_geometry::Hit;

use super::LANES;
use crate::integrators::pass::{PassEstimator, pass_items_until, pixel_of};
use crate::integrators::path_tracer::{CameraPath, Connection, PathTracer, Shading, Vertex};
use crate::sampler::PassSamplers;
use crate::{ChunkSampler, ChunkWork, Splat, TraceStats};

/// The paths in flight, as a structure of arrays: one entry per lane in each. A lane keeps its
/// slot from its first ray to its splat and a new path is written into a free slot in place, so
/// no path is moved while it is traced.
struct Lanes<'a> {
    /// The paths (pixel, wavelengths, throughput, radiance, next ray).
    paths: Vec<CameraPath>,
    /// Each path's own sampler.
    rngs: Vec<ChunkSampler>,
    /// Which slots hold a path in flight (bit `i`: slot `i`).
    live: u32,
    /// What each lane's ray hit this round.
    hits: [Option<Hit>; LANES],
    /// The vertex each lane reached this round (`None`: the path ends).
    vertices: [Option<Vertex<'a>>; LANES],
    /// The lanes in shading order, as sort keys: the primitive hit (`u32::MAX`: nothing) in the
    /// high half, the slot in the low half (one integer sorts faster than a pair).
    order: Vec<u64>,
    /// Next-event estimation's queued samples: the lane and the connection.
    queue: Vec<(usize, Connection)>,
}

/// Every slot's bit (the live mask is a `u32`).
const ALL_SLOTS: u32 = u32::MAX >> (32 - LANES);
const _: () = assert!(LANES >= 1 && LANES <= 32);

/// The slots set in `mask`, lowest first.
fn slots(mask: u32) -> impl Iterator<Item = usize> {
    let mut rest = mask;
    std::iter::from_fn(move || {
        (rest != 0).then(|| {
            let i = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            i
        })
    })
}

/// Renders the camera samples of pass `work.chunk` (`work.items` pixels, or a prefix of them
/// once `work.deadline` has passed) with the batched kernel into `film`; the returned
/// `stats.beams` counts them.
pub(crate) fn render_pass<'a>(
    tracer: &PathTracer<'a>,
    work: ChunkWork,
    film: &mut dyn Splat,
) -> TraceStats {
    let mut stats = TraceStats::default();
    let mut items = pass_items_until(work.chunk, work.items, tracer.items(), work.deadline);
    let mut lanes = Lanes::<'a> {
        paths: Vec::with_capacity(LANES),
        rngs: Vec::with_capacity(LANES),
        live: 0,
        hits: std::array::from_fn(|_| None),
        vertices: std::array::from_fn(|_| None),
        order: Vec::with_capacity(LANES),
        queue: Vec::with_capacity(2 * LANES),
    };
    let samplers = PassSamplers::new(tracer.scene().sampler(), work.seed, work.chunk);
    loop {
        lanes.generate(tracer, &samplers, &mut items, &mut stats);
        if lanes.live == 0 {
            return stats;
        }
        lanes.intersect(tracer);
        lanes.shade(tracer, &mut stats);
        lanes.shadow_and_connect(tracer, &mut stats);
        lanes.go_on_or_splat(tracer, film, &mut stats);
    }
}

impl<'a> Lanes<'a> {
    /// Stage 1: free slots take the next items, their paths written in place.
    fn generate(
        &mut self,
        tracer: &PathTracer<'a>,
        samplers: &PassSamplers,
        items: &mut impl Iterator<Item = u64>,
        stats: &mut TraceStats,
    ) {
        let width = u64::from(tracer.scene().camera.width());
        for i in slots(!self.live & ALL_SLOTS) {
            let Some(item) = items.next() else { break };
            let (px, py) = pixel_of(item, width);
            let rng = samplers.get(item);
            if i < self.paths.len() {
                self.rngs[i] = rng;
                tracer.restart(&mut self.paths[i], px, py, &mut self.rngs[i]);
            } else {
                // Slots are taken lowest first, so a new slot is the next one.
                self.rngs.push(rng);
                let path = tracer.start(px, py, &mut self.rngs[i]);
                self.paths.push(path);
            }
            self.live |= 1 << i;
            stats.beams += 1;
        }
    }

    /// Stage 2: every lane's closest hit.
    fn intersect(&mut self, tracer: &PathTracer<'a>) {
        let world = tracer.scene().world;
        for i in slots(self.live) {
            self.hits[i] = world.intersect(&self.paths[i].state.ray, f64::INFINITY);
        }
    }

    /// Stage 3: the lanes in material order; each one's arrival and its light samples, queued.
    fn shade(&mut self, tracer: &PathTracer<'a>, stats: &mut TraceStats) {
        self.order.clear();
        self.order.extend(slots(self.live).map(|i| {
            let primitive = self.hits[i].as_ref().map_or(u32::MAX, |h| h.primitive);
            (u64::from(primitive) << 32) | i as u64
        }));
        self.order.sort_unstable();
        self.queue.clear();
        for &key in &self.order {
            let i = (key & u64::from(u32::MAX)) as usize;
            self.vertices[i] = None;
            let Some(hit) = &self.hits[i] else { continue };
            let path = &mut self.paths[i];
            let vertex = tracer.arrive(
                &mut path.state,
                hit,
                &mut path.lambda_weights,
                &mut self.rngs[i],
                stats,
            );
            self.vertices[i] = vertex;
            let Some(vertex) = self.vertices[i].as_ref().filter(|v| v.next_event) else { continue };
            let at = Shading { hit, wo: -path.state.ray.direction, material: &*vertex.material };
            let queue = &mut self.queue;
            tracer.for_each_light(hit, vertex.light, |light| {
                if let Some(c) = tracer.connection(&path.state, &at, light) {
                    queue.push((i, c));
                }
            });
        }
    }

    /// Stages 4 and 5: the queued shadow rays, each unoccluded sample's light added to its
    /// path as soon as its ray is tested (no second pass over the queue).
    fn shadow_and_connect(&mut self, tracer: &PathTracer<'a>, stats: &mut TraceStats) {
        let scene = tracer.scene();
        for (i, c) in &self.queue {
            if !c.shadow.visible(scene) {
                continue;
            }
            let (Some(hit), Some(vertex)) = (&self.hits[*i], &self.vertices[*i]) else { continue };
            let path = &mut self.paths[*i];
            let at = Shading { hit, wo: -path.state.ray.direction, material: &*vertex.material };
            tracer.connect(&mut path.state, &at, c, stats);
        }
    }

    /// Stages 6 and 7: each lane's next direction, or its sample on the film and its slot
    /// freed.
    fn go_on_or_splat(
        &mut self,
        tracer: &PathTracer<'a>,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        for i in slots(self.live) {
            let alive = match (&self.hits[i], self.vertices[i].take()) {
                (Some(hit), Some(vertex)) => {
                    tracer.go_on(&mut self.paths[i].state, hit, vertex, &mut self.rngs[i], stats)
                }
                _ => false,
            };
            if !alive {
                tracer.finish(&self.paths[i], film);
                self.live &= !(1 << i);
            }
        }
    }
}
