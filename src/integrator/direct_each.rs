//! `direct` packet by packet ([`EachPacket`]): under light sampling alone with one light per
//! sample drawn from the light table, each camera packet is gathered into one hit record and
//! shaded at once, instead of through the tile's wavefront of records (see [`each_packet`]).

use super::{area_sample, light_event, Buffers, LightTable, LIGHT_CHOICE, LIGHT_POINT};
use crate::accel::{Hits8, RayHit8};
use crate::bsdf::LobeSet;
use crate::integrator::context::{masked, TileCtx};
use crate::integrator::light_term::AreaChoice;
use crate::integrator::primary::EachPacket;
use crate::integrator::settings::Integrator;
use crate::light::emitters::LightSample8;
use crate::light::select::LightChoice;
use crate::scene::build::Scene;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// Whether `direct` shades packet by packet ([`super::primary::tile_each`], [`Each`]): light samples
/// alone, one light each, from the light table (not per-sample streams), nothing outside the
/// scene's area lights, and triangles only. The same radiance as the wavefront, bit for bit; the
/// sampler replay logs its table streams (`replay::table_streams`), so a recording render draws
/// as the render it measures (it used to fall back to the wavefront's point-by-point draws, and
/// `strata profile` replayed hw2 analytic's pmj02 at twice its instrumented cost). Measured
/// (CPU seconds, 1 thread, best of 9-13 under load): hw2 analytic 8 % faster (the wavefront's
/// 70 KiB of hit records a tile no longer cycle through L2), hw2 sphere 4 % slower (its sphere
/// lanes gather lane by lane; callgrind's caches do not show why), so scenes with spheres or
/// ellipsoids keep the wavefront.
pub(super) fn each_packet(it: &Integrator, scene: &Scene) -> bool {
    let d = it.direct;
    d.emitter_sampling
        && d.bsdf_samples == 0
        && it.light_selection.picks_one()
        && !it.light_streams()
        && !scene.emitters.is_empty()
        && scene.sky.is_none()
        && scene.envmap.is_none()
        && scene.delta.is_empty()
        && scene.ell_material.is_empty()
}

/// [`super::shade_one`] packet by packet ([`EachPacket`]): the light points of pixel sample s
/// drawn for every packet with a hit lane before any is shaded (back to back, as the wavefront
/// draws them), then each packet's light samples at its hits, their shadow rays traced together
/// at the end of the sample.
pub(super) struct Each<'a, L> {
    it: &'a Integrator,
    buf: &'a mut Buffers,
    /// pixel sample s's constants
    one: Option<OneLight>,
    /// whether `buf.table_streams` holds the light point's streams of the tile's packets (made
    /// at the batch's first sample; none for a grid layout)
    streamed: Option<bool>,
    lobes: std::marker::PhantomData<L>,
}

/// The fewest samples of a batch for which [`Each`] draws the light points from streams.
const STREAM_BATCH: usize = 8;

/// [`super::shade_one`]'s per-sample constants.
struct OneLight {
    one_light: bool,
    own_choice: bool,
    choice_table: LightTable,
    inv_n: F8,
}

impl<'a, L> Each<'a, L> {
    /// `direct` (`it`) shading with the buffers `buf`, for a batch of `samples` pixel samples:
    /// the light points come from per-packet streams when the batch has at least
    /// [`STREAM_BATCH`] samples (a stream costs about five points' hashing: callgrind, pmj02),
    /// else point by point. The same points either way.
    pub(super) fn new(it: &'a Integrator, buf: &'a mut Buffers, samples: usize) -> Self {
        let streamed = (samples < STREAM_BATCH).then_some(false);
        Self { it, buf, one: None, streamed, lobes: std::marker::PhantomData }
    }
}

impl<L: LobeSet> EachPacket for Each<'_, L> {
    fn begin(&mut self, ctx: &mut TileCtx, s: u32, packets: &[(RayHit8, Mask8)]) {
        let it = self.it;
        let smp = &ctx.samples;
        let one_light = it.light_sampler.certain();
        let table = LightTable::new(it, smp, LIGHT_POINT.first, s);
        self.one = Some(OneLight {
            one_light,
            own_choice: !one_light && it.light_choice == LightChoice::Dimension,
            choice_table: LightTable::new(it, smp, LIGHT_CHOICE.first, s),
            inv_n: F8::splat(1.0 / it.light_set.n() as f32),
        });
        // The light point's streams, hashed once per pixel for the batch's samples.
        let Buffers { uv, table_streams, .. } = &mut *self.buf;
        let streamed = *self.streamed.get_or_insert_with(|| table.streams(smp, ctx.pks, table_streams));
        // The light points of every packet that hit something (a point is a pure function of its
        // pixel and index: drawing it for a packet that turns out to shade nothing changes no
        // other).
        let n = it.light_set.n();
        uv.clear();
        for (i, ((rh, traced), pk)) in packets.iter().zip(ctx.pks).enumerate() {
            let hit = Hits8::from_rayhit(rh, *traced).hit.any();
            for k in 0..n {
                uv.push(match (hit, streamed) {
                    (false, _) => (F8::ZERO, F8::ZERO),
                    (true, true) => table.stream_point(smp, &table_streams[i], i, k),
                    (true, false) => table.point(smp, pk.pixel, k),
                });
            }
        }
        self.buf.batch.clear();
    }

    #[inline(always)]
    fn shade(&mut self, ctx: &mut TileCtx, sh: &SurfaceHit8, i: usize, _: &mut Vec3x8) {
        let shade = sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)));
        if shade.none() {
            return;
        }
        let (it, Some(c)) = (self.it, &self.one) else { return };
        let TileCtx { scene, pks, samples: smp, .. } = ctx;
        let eps = scene.offset_eps(sh.p);
        let n = it.light_set.n() as usize;
        let mut ls = LightSample8::ZERO;
        for k in 0..n {
            let uv = self.buf.uv[i * n + k];
            let choice = if c.one_light {
                AreaChoice::Certain
            } else if c.own_choice {
                AreaChoice::Drawn(c.choice_table.point(smp, pks[i].pixel, k as u32).0)
            } else {
                AreaChoice::Reuse
            };
            let ok = area_sample(it, scene, sh, shade, choice, uv, &mut ls);
            let weigh = |ls: &LightSample8, f: Vec3x8, g: F8, lit: Mask8| {
                let g = g * ls.area * ls.inv_pmf * c.inv_n;
                masked(f.mul_elem(ls.radiance).scale(g), lit)
            };
            if let Some((contrib, ray)) = light_event::<L>(scene, sh, eps, &ls, ok, weigh, None) {
                self.buf.batch.contrib.push(contrib);
                self.buf.batch.push(ray, i);
            }
        }
    }

    fn end(&mut self, ctx: &mut TileCtx, out: &mut [Vec3x8]) {
        self.buf.batch.trace(&mut ctx.tracer, out);
    }
}

#[cfg(test)]
mod tests {
    use super::super::{shade, Direct, DirectScratch};
    use super::*;
    use crate::bsdf::{AllLobes, Diffuse};
    use crate::camera::{tile_packets, FirstSample};
    use crate::integrator::context::Tracer;
    use crate::integrator::estimator::Estimator;
    use crate::integrator::primary;
    use crate::integrator::samples::Samples;
    use crate::integrator::settings::SamplerChoice;
    use crate::integrator::stats::Counters;
    use crate::sampler::SamplerKind;
    use crate::scene::{limits::Limits, parse::parse_str};

    /// An analytic-like scene: a floor of two triangles (two diffuse materials) under `lights`
    /// quad lights, half the image sky.
    fn scene(lights: usize) -> Scene {
        let mut text = String::from(
            "size 24 20\ncamera 0.0001 0 -4 0 0 0 0 1 0 45\nmaxverts 4\n\
             vertex -10 -1 -10\nvertex -10 -1 10\nvertex 10 -1 -10\nvertex 10 -1 10\n\
             diffuse 0.3 0.3 0.5\ntri 0 1 2\ndiffuse 0.6 0.2 0.1\ntri 1 3 2\n",
        );
        for l in 0..lights {
            text += &format!("quadLight {} 1 -1 0 0 2 2 0 0 {} 5 5\n", l as f32 * 1.5 - 1.0, 2 + 3 * l);
        }
        let desc = parse_str(&text, std::path::Path::new("t.test"), &Limits::default()).expect("scene");
        Scene::build(desc).expect("build")
    }

    /// The bits of every pixel sample's radiance of `direct` over the image, tile by tile, packet
    /// by packet (`each`) or through the wavefront (`shade` at the tile's hit records).
    fn radiance<L: LobeSet>(it: &Integrator, scene: &Scene, each: bool) -> Vec<[u32; 3]> {
        let (w, h) = (scene.desc.width, scene.desc.height);
        let (mut sc, mut c, mut bits) = (DirectScratch::default(), Counters::default(), Vec::new());
        for (tx, ty) in (0..h).step_by(16).flat_map(|y| (0..w).step_by(16).map(move |x| (x, y))) {
            let pks = tile_packets(tx, ty, 16, 16, w, h);
            let samples = Samples::new(it, it.camera(scene));
            let mut ctx = TileCtx { scene, samples, pks: &pks, tracer: Tracer::new(scene, &mut c, None) };
            let mut out = Vec::new();
            if each {
                Direct::tile::<L>(it, &mut ctx, &mut sc, 0..it.spp, &mut out);
            } else {
                let DirectScratch { wave, buf, bsdf } = &mut sc;
                primary::tile(&mut ctx, wave, 0..it.spp, &mut out, |ctx, hits, s, out| {
                    shade::<L>(it, ctx, hits, buf, bsdf, s, out)
                });
            }
            bits.extend(out.iter().flat_map(|v| {
                let (x, y, z) = (v.x.to_array(), v.y.to_array(), v.z.to_array());
                (0..8).map(move |i| [x[i].to_bits(), y[i].to_bits(), z[i].to_bits()])
            }));
        }
        bits
    }

    /// `direct` packet by packet gives the wavefront's radiance bit for bit: one light (its
    /// choice certain) and two (chosen from the light point's u, or from a dimension of their
    /// own), one and two light samples, three samplers, batches whose light points are drawn point
    /// by point and from streams, the diffuse and the general kernel.
    #[test]
    fn packet_by_packet_matches_the_wavefront_bit_for_bit() {
        for (lights, n, choice) in
            [(1, 1, LightChoice::Reuse), (2, 1, LightChoice::Reuse), (2, 2, LightChoice::Dimension)]
        {
            let sc = scene(lights);
            // 4 spp: the light points drawn point by point; 8 (`STREAM_BATCH`): from streams.
            let runs = [SamplerKind::INDEPENDENT, SamplerKind::SOBOL, SamplerKind::PMJ02].map(|k| (k, 4)).into_iter();
            for (kind, spp) in runs.chain([(SamplerKind::SOBOL, 8), (SamplerKind::PMJ02, 8)]) {
                let samplers = SamplerChoice { sampler: None, pixel: Some(kind), light: Some(kind) };
                let mut it = Integrator::new(&sc, spp, 3, samplers, Some(n));
                it.first_sample = FirstSample::Jittered;
                it.set_light_selection(&sc, "uniform".parse().expect("selection"));
                it.light_choice = choice;
                assert!(each_packet(&it, &sc), "{lights} lights, {n} samples: packet by packet");
                let what = format!("{lights} lights, {n} light samples, {kind:?}, {spp} spp");
                let each = radiance::<Diffuse>(&it, &sc, true);
                assert!(each.iter().any(|p| p[0] != 0), "{what}: some light");
                assert_eq!(each, radiance::<Diffuse>(&it, &sc, false), "{what}");
                assert_eq!(radiance::<AllLobes>(&it, &sc, true), radiance::<AllLobes>(&it, &sc, false), "{what}");
            }
        }
    }
}
