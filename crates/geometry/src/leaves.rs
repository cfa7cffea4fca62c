//! The primitives behind the BVH's leaves, and the tests the traversal runs on a leaf.
//!
//! A primitive slot is a whole analytic shape or one mesh triangle, in BVH leaf order. Each leaf
//! also keeps its triangles' world-space vertices as SIMD lanes ([`Triangles4`], four slots per
//! packet), so the traversal filters all of a leaf's triangles with one
//! [`TriangleRay::candidates4`] and runs the scalar watertight test only on the lanes that pass.
//! The filter is the scalar test's first half with the same arithmetic in every lane, so it
//! never drops a triangle the scalar test accepts, and every reported hit comes from the scalar
//! test: results are those of a primitive-by-primitive search.
//!
//! Two layout choices keep a ray's chain of dependent loads short (measured with the `ray_rate`
//! example, see the crate README): a packet carries its lanes' shape and triangle index, so the
//! winning triangle's hit needs no slot lookup; and in a world of meshes only every leaf is the
//! packet of the same number, so a leaf's packet is loaded without reading its record first.

use glam::DVec3;
use wide::f64x4;

use crate::bvh::Leaf;
use crate::mesh::{TriangleRay, Triangles4};
use crate::{Hit, Ray, Shape};

/// Lanes per triangle packet.
const LANES: usize = 4;

/// What a primitive slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SlotKind {
    /// A mesh triangle, tested in its leaf's packet lane.
    Triangle,
    /// A triangle that no ray hits (its normal has zero length, which `Mesh` refuses).
    Never,
    /// A whole analytic shape: its own routine.
    Analytic,
}

/// One primitive slot: the shape and its primitive index.
#[derive(Debug, Clone, Copy)]
struct Slot {
    shape: u32,
    index: u32,
    kind: SlotKind,
}

/// One leaf: its slots `first..first + count`, its packets `packet..packet + packets` (one per
/// four slots, none when the leaf holds no triangle) and whether it holds any analytic shape.
#[derive(Debug, Clone, Copy)]
struct LeafRecord {
    first: u32,
    count: u32,
    packet: u32,
    packets: u32,
    analytic: bool,
}

/// The nearest candidate so far of a closest-hit query.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Nearest {
    /// None yet.
    None,
    /// A triangle slot, its vertices, and the distance and barycentrics its test found (the
    /// full hit is built once, at the end).
    Triangle { shape: u32, index: u32, vertices: [DVec3; 3], t: f64, b: [f64; 3] },
    /// An analytic shape's full hit.
    Hit(Hit),
}

/// All slots and leaves of a world's BVH.
#[derive(Debug, Clone, Default)]
pub(crate) struct Leaves {
    slots: Vec<Slot>,
    leaves: Vec<LeafRecord>,
    packets: Vec<Packet>,
    has_triangles: bool,
    /// Every leaf is one packet of triangles, numbered as the leaf (meshes whose leaves hold
    /// at most four triangles): a leaf's packet is found without reading its record first, so
    /// the two loads overlap instead of waiting one for the other.
    packet_per_leaf: bool,
}

impl Leaves {
    /// The slots of `prims` (`(shape, primitive)` pairs) in the BVH's leaf order `order`
    /// (`obvhs`'s `primitive_indices`), and the packets of `leaves`.
    pub(crate) fn new(
        shapes: &[Shape],
        prims: &[(u32, u32)],
        order: &[u32],
        leaves: &[Leaf],
    ) -> Self {
        let mut vertices = Vec::with_capacity(order.len());
        let mut slots = Vec::with_capacity(order.len());
        for &p in order {
            let (shape, index) = prims[p as usize];
            let (kind, v) = match shapes[shape as usize].triangle_mesh() {
                Some(mesh) => match mesh.triangle(index) {
                    Some((v, true)) => (SlotKind::Triangle, v),
                    _ => (SlotKind::Never, [[0.0; 3]; 3]),
                },
                None => (SlotKind::Analytic, [[0.0; 3]; 3]),
            };
            slots.push(Slot { shape, index, kind });
            vertices.push(v);
        }
        let mut packets = Vec::new();
        let records: Vec<LeafRecord> = leaves
            .iter()
            .map(|leaf| {
                let range = leaf.first as usize..(leaf.first + leaf.count) as usize;
                let (kinds, vertices) = (&slots[range.clone()], &vertices[range]);
                let packet = packets.len() as u32;
                // Mesh leaves get packets even when all their triangles are degenerate (their
                // lanes are zeros, which the filter rejects), so that every leaf of a mesh is
                // one packet.
                if kinds.iter().any(|s| s.kind != SlotKind::Analytic) {
                    for (k, v) in kinds.chunks(LANES).zip(vertices.chunks(LANES)) {
                        packets.push(packet_of(k.iter().copied().zip(v.iter().copied())));
                    }
                }
                let packets = packets.len() as u32 - packet;
                let analytic = kinds.iter().any(|s| s.kind == SlotKind::Analytic);
                LeafRecord { first: leaf.first, count: leaf.count, packet, packets, analytic }
            })
            .collect();
        let has_triangles = slots.iter().any(|s| s.kind == SlotKind::Triangle);
        let packet_per_leaf = records.iter().enumerate().all(|(i, r): (usize, &LeafRecord)| {
            r.packets == 1 && r.packet as usize == i && !r.analytic
        });
        Self { slots, leaves: records, packets, has_triangles, packet_per_leaf }
    }

    /// Number of primitive slots.
    pub(crate) fn slot_count(&self) -> usize {
        self.slots.len()
    }

    /// Number of leaves.
    pub(crate) fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    /// The per-ray triangle setup, if any slot is a triangle.
    #[inline]
    pub(crate) fn triangle_ray(&self, ray: &Ray) -> Option<TriangleRay> {
        self.has_triangles.then(|| TriangleRay::new(ray))
    }

    /// Tests every primitive of `leaf` closer than `limit`, recording the nearest in `best`;
    /// the new limit if one was closer.
    #[inline]
    pub(crate) fn nearest(
        &self,
        leaf: u32,
        shapes: &[Shape],
        ray: &Ray,
        triangle_ray: Option<&TriangleRay>,
        mut limit: f64,
        best: &mut Nearest,
    ) -> Option<f64> {
        if self.packet_per_leaf
            && let Some(tr) = triangle_ray
        {
            return self.nearest_in_packet(leaf, tr, limit, best);
        }
        let record = self.leaves[leaf as usize];
        let mut closer = None;
        if let Some(tr) = triangle_ray {
            for packet in self.packets_of(record) {
                if let Some(t) = packet.nearest(tr, limit, best) {
                    limit = t;
                    closer = Some(t);
                }
            }
        }
        if record.analytic {
            for slot in self.analytic_slots(record) {
                let shape = &shapes[slot.shape as usize];
                if let Some(mut hit) = shape.primitives().intersect(slot.index, ray, limit) {
                    hit.primitive = slot.shape;
                    *best = Nearest::Hit(hit);
                    limit = hit.t;
                    closer = Some(hit.t);
                }
            }
        }
        closer
    }

    /// [`Leaves::nearest`] for a world whose every leaf is the packet of the same number: the
    /// leaf's record is read only for a triangle that is hit.
    #[inline]
    fn nearest_in_packet(
        &self,
        leaf: u32,
        tr: &TriangleRay,
        limit: f64,
        best: &mut Nearest,
    ) -> Option<f64> {
        self.packets[leaf as usize].nearest(tr, limit, best)
    }

    /// Whether any primitive of `leaf` lies on the ray with `0 < t < limit`.
    #[inline]
    pub(crate) fn any(
        &self,
        leaf: u32,
        shapes: &[Shape],
        ray: &Ray,
        triangle_ray: Option<&TriangleRay>,
        limit: f64,
    ) -> bool {
        if self.packet_per_leaf
            && let Some(tr) = triangle_ray
        {
            return self.packets[leaf as usize].any(tr, limit);
        }
        let record = self.leaves[leaf as usize];
        if let Some(tr) = triangle_ray
            && self.packets_of(record).iter().any(|p| p.any(tr, limit))
        {
            return true;
        }
        record.analytic
            && self
                .analytic_slots(record)
                .any(|slot| shapes[slot.shape as usize].hit_t(slot.index, ray, limit).is_some())
    }

    /// The full hit of the nearest candidate, with the world's indices filled in.
    pub(crate) fn hit(&self, nearest: Nearest, shapes: &[Shape]) -> Option<Hit> {
        match nearest {
            Nearest::None => None,
            Nearest::Hit(hit) => Some(hit),
            Nearest::Triangle { shape, index, vertices, t, b } => {
                let mesh = shapes[shape as usize].triangle_mesh()?;
                let mut hit = mesh.hit_at(index, vertices, t, b)?;
                hit.primitive = shape;
                Some(hit)
            }
        }
    }

    /// The packets of a leaf's slots (none for a leaf without triangles).
    #[inline(always)]
    fn packets_of(&self, record: LeafRecord) -> &[Packet] {
        let first = record.packet as usize;
        &self.packets[first..first + record.packets as usize]
    }

    /// The analytic slots of a leaf.
    fn analytic_slots(&self, record: LeafRecord) -> impl Iterator<Item = &Slot> {
        let range = record.first as usize..(record.first + record.count) as usize;
        self.slots[range].iter().filter(|s| s.kind == SlotKind::Analytic)
    }
}

/// Up to four slots of a leaf: their triangles' vertices as SIMD lanes, for
/// [`TriangleRay::candidates4`], and each lane's shape and triangle index, so that a hit needs
/// no other lookup (a lane that is not a triangle holds zeros, which the filter rejects).
#[derive(Debug, Clone, Copy)]
struct Packet {
    vertices: Triangles4,
    shape: [u32; LANES],
    index: [u32; LANES],
}

impl Packet {
    /// Tests the packet's triangles closer than `limit` (the filter, then the scalar test on the
    /// lanes that pass, in lane order), recording the nearest in `best`; the new limit if one
    /// was closer.
    #[inline(always)]
    fn nearest(&self, tr: &TriangleRay, mut limit: f64, best: &mut Nearest) -> Option<f64> {
        let mut lanes = tr.candidates4(&self.vertices);
        let mut closer = None;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let vertices = lane_vertices(&self.vertices, lane);
            let Some((t, b)) = tr.intersect(&vertices.map(|v| v.to_array()), limit) else {
                continue;
            };
            let (shape, index) = (self.shape[lane], self.index[lane]);
            *best = Nearest::Triangle { shape, index, vertices, t, b };
            limit = t;
            closer = Some(t);
        }
        closer
    }

    /// Whether any of the packet's triangles lies on the ray with `0 < t < limit`.
    #[inline(always)]
    fn any(&self, tr: &TriangleRay, limit: f64) -> bool {
        let mut lanes = tr.candidates4(&self.vertices);
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let vertices = lane_vertices(&self.vertices, lane).map(|v| v.to_array());
            if tr.intersect(&vertices, limit).is_some() {
                return true;
            }
        }
        false
    }
}

/// The packet of up to four slots and their vertices (zeros for a slot that is no triangle).
fn packet_of(slots: impl Iterator<Item = (Slot, [[f64; 3]; 3])>) -> Packet {
    let mut lanes = [[[0.0; LANES]; 3]; 3];
    let (mut shape, mut index) = ([0; LANES], [0; LANES]);
    for (lane, (slot, v)) in slots.enumerate() {
        if slot.kind == SlotKind::Triangle {
            for (vertex, p) in v.iter().enumerate() {
                for axis in 0..3 {
                    lanes[vertex][axis][lane] = p[axis];
                }
            }
            (shape[lane], index[lane]) = (slot.shape, slot.index);
        }
    }
    Packet { vertices: lanes.map(|v| v.map(f64x4::from)), shape, index }
}

/// The vertices in lane `lane` of a packet.
#[inline(always)]
fn lane_vertices(packet: &Triangles4, lane: usize) -> [DVec3; 3] {
    let c = |vertex: usize, axis: usize| packet[vertex][axis].as_array_ref()[lane];
    [0, 1, 2].map(|v| DVec3::new(c(v, 0), c(v, 1), c(v, 2)))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use crate::bench_scenes::bumpy_sphere_triangles;
    use crate::{Mesh, Ray, Shape, Sphere, World};
    use glam::DVec3;

    /// A degenerate triangle far from the others sits in a leaf of its own: that leaf still
    /// gets a packet (of zeros, which the filter rejects), so a mesh world keeps the
    /// packet-per-leaf layout; it loses it once an analytic shape shares the tree.
    #[test]
    fn a_mesh_world_has_one_packet_per_leaf_and_a_mixed_one_does_not() {
        let (mut positions, mut triangles) = bumpy_sphere_triangles(8);
        let n = positions.len() as u32;
        positions.extend([DVec3::new(100.0, 0.0, 0.0), DVec3::new(101.0, 0.0, 0.0)]);
        positions.push(DVec3::new(102.0, 0.0, 0.0));
        triangles.push([n, n + 1, n + 2]);
        let mesh: Shape = Mesh::from_triangles(positions, triangles).unwrap().into();
        let world = World::new(vec![mesh.clone()]).unwrap();
        let lone = |l: &super::LeafRecord| {
            let slots = &world.leaves.slots[l.first as usize..(l.first + l.count) as usize];
            slots.iter().all(|s| s.kind == super::SlotKind::Never)
        };
        assert!(world.leaves.leaves.iter().any(lone), "a leaf holds only the degenerate one");
        assert!(world.leaves.packet_per_leaf);
        let ray = Ray::new(DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z);
        assert_eq!(
            world.intersect(&ray, f64::INFINITY),
            world.intersect_brute_force(&ray, f64::INFINITY)
        );
        let sphere: Shape = Sphere::new(DVec3::new(5.0, 0.0, 0.0), 1.0).unwrap().into();
        let mixed = World::new(vec![mesh, sphere]).unwrap();
        assert!(!mixed.leaves.packet_per_leaf);
    }
}
