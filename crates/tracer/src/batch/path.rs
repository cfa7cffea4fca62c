//! The path tracer's batched kernel: one pass's camera samples in a batch of [`LANES`] lanes,
//! stage by stage (see the module above for the stages and why they give the scalar image).

use spectrace_geometry::Hit;

use super::LANES;
use crate::integrators::pass::{PassEstimator, pass_items_until, pixel_of};
use crate::integrators::path_tracer::{CameraPath, Connection, PathTracer, Shading, Vertex};
use crate::{ChunkSampler, ChunkWork, Splat, TraceStats};

/// The paths in flight, as a structure of arrays: one entry per lane in each.
struct Lanes<'a> {
    /// The paths (pixel, wavelengths, throughput, radiance, next ray).
    paths: Vec<CameraPath>,
    /// Each path's own sampler.
    rngs: Vec<ChunkSampler>,
    /// What each lane's ray hit this round.
    hits: Vec<Option<Hit>>,
    /// The vertex each lane reached this round (`None`: the path ends).
    vertices: Vec<Option<Vertex<'a>>>,
    /// The lanes in shading order: by the primitive hit (`u32::MAX`: nothing).
    order: Vec<(u32, usize)>,
    /// Next-event estimation's queued samples: the lane and the connection.
    queue: Vec<(usize, Connection)>,
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
        hits: Vec::with_capacity(LANES),
        vertices: Vec::with_capacity(LANES),
        order: Vec::with_capacity(LANES),
        queue: Vec::with_capacity(2 * LANES),
    };
    loop {
        lanes.generate(tracer, work, &mut items, &mut stats);
        if lanes.paths.is_empty() {
            return stats;
        }
        lanes.intersect(tracer);
        lanes.shade(tracer, &mut stats);
        lanes.shadow_and_connect(tracer, &mut stats);
        lanes.go_on_or_splat(tracer, film, &mut stats);
    }
}

impl<'a> Lanes<'a> {
    /// Stage 1: free lanes take the next items.
    fn generate(
        &mut self,
        tracer: &PathTracer<'a>,
        work: ChunkWork,
        items: &mut impl Iterator<Item = u64>,
        stats: &mut TraceStats,
    ) {
        let kind = tracer.scene().sampler();
        let width = u64::from(tracer.scene().camera.width());
        while self.paths.len() < LANES {
            let Some(item) = items.next() else { break };
            let (px, py) = pixel_of(item, width);
            let mut rng = ChunkSampler::for_path(kind, work.seed, work.chunk, item);
            self.paths.push(tracer.start(px, py, &mut rng));
            self.rngs.push(rng);
            stats.beams += 1;
        }
    }

    /// Stage 2: every lane's closest hit.
    fn intersect(&mut self, tracer: &PathTracer<'a>) {
        let world = tracer.scene().world;
        self.hits.clear();
        self.hits.extend(self.paths.iter().map(|p| world.intersect(&p.state.ray, f64::INFINITY)));
    }

    /// Stage 3: the lanes in material order; each one's arrival and its light samples, queued.
    fn shade(&mut self, tracer: &PathTracer<'a>, stats: &mut TraceStats) {
        self.order.clear();
        self.order.extend(
            self.hits
                .iter()
                .enumerate()
                .map(|(i, h)| (h.as_ref().map_or(u32::MAX, |h| h.primitive), i)),
        );
        self.order.sort_unstable();
        self.vertices.clear();
        self.vertices.resize(self.paths.len(), None);
        self.queue.clear();
        for &(_, i) in &self.order {
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

    /// Stages 4 and 5: the queued shadow rays, then the unoccluded samples' light.
    fn shadow_and_connect(&mut self, tracer: &PathTracer<'a>, stats: &mut TraceStats) {
        let scene = tracer.scene();
        self.queue.retain(|(_, c)| c.shadow.visible(scene));
        for (i, c) in &self.queue {
            let (Some(hit), Some(vertex)) = (&self.hits[*i], &self.vertices[*i]) else { continue };
            let path = &mut self.paths[*i];
            let at = Shading { hit, wo: -path.state.ray.direction, material: &*vertex.material };
            tracer.connect(&mut path.state, &at, c, stats);
        }
    }

    /// Stages 6 and 7: each lane's next direction, or its sample on the film and its lane
    /// freed.
    fn go_on_or_splat(
        &mut self,
        tracer: &PathTracer<'a>,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        for i in (0..self.paths.len()).rev() {
            let alive = match (&self.hits[i], self.vertices[i].take()) {
                (Some(hit), Some(vertex)) => {
                    tracer.go_on(&mut self.paths[i].state, hit, vertex, &mut self.rngs[i], stats)
                }
                _ => false,
            };
            if !alive {
                tracer.finish(&self.paths[i], film);
                self.paths.swap_remove(i);
                self.rngs.swap_remove(i);
            }
        }
    }
}
