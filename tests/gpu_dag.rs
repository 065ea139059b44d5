//! The DAG's cut on the device (`meshslim::dag::gpu`, lavapipe in CI): every cluster's draw and
//! the counts against the CPU twin (`dag::cut::dag_cut`) from several cameras, with and without
//! the frustum; the drawn set with no frustum is the command line's `cut_from_camera`, cluster
//! for cluster. With CI=true a missing adapter fails.

use crate::common;

use common::*;
use glam::{Mat4, Vec3};
use meshslim::compute::types::CornerDraw;
use meshslim::dag::cut::{dag_cut, frustum_planes};
use meshslim::dag::gpu::GpuCut;
use meshslim::dag::{self, CameraCut, DagOptions};
use meshslim::mesh;

/// The draws and counts both ways, equal to the bit on an adapter that rounds as the CPU does;
/// elsewhere a fused multiply-add may flip a cluster within an ulp of the threshold, so at most
/// one in a thousand may differ.
fn compare(what: &str, gpu: &(Vec<CornerDraw>, [u32; 4]), cpu: &(Vec<CornerDraw>, [u32; 4])) {
    if rounds_like_the_cpu() {
        assert_eq!(gpu.0, cpu.0, "{what}: draws");
        assert_eq!(gpu.1, cpu.1, "{what}: counts");
    } else {
        let differ = gpu.0.iter().zip(&cpu.0).filter(|(g, c)| g != c).count();
        assert!(
            differ * 1000 <= cpu.0.len(),
            "{what}: {differ} draws differ"
        );
    }
}

#[test]
fn the_device_cut_is_its_twins_draw_for_draw() {
    let Some(ctx) = gpu_context() else { return };
    for (name, m) in [
        ("noisy_sphere", mesh::noisy_sphere(5, 0.01, 7)),
        ("torus", mesh::torus(1.0, 0.3, 160, 80)),
    ] {
        let (d, _) = dag::build(&m, &DagOptions::default()).unwrap();
        let clusters = d.cut_clusters();
        let mut gpu = GpuCut::new(&ctx.pipelines, &ctx.queue, &clusters).unwrap();
        assert_eq!(gpu.clusters() as usize, d.clusters.len());
        let r = d.diagonal;
        let mut any_culled = false;
        for (eye, pixels) in [
            ([0.0, 0.0, 0.6 * r], 1.0),
            ([0.0, 0.0, 3.0 * r], 1.0),
            ([r, -r, r], 0.25),
            ([0.1 * r, 0.45 * r, 0.0], 4.0),
            ([0.0, 0.0, 40.0 * r], 1.0),
        ] {
            let cam = CameraCut {
                eye,
                pixels,
                fov_deg: 60.0,
                height: 720.0,
            };
            let at = format!("{name} from {eye:?} at {pixels} px");
            // No frustum: the drawn clusters are the command line's cut.
            let p = cam.params(clusters.len());
            let mut cpu = (vec![CornerDraw::default(); clusters.len()], [0; 4]);
            dag_cut(&p, &clusters, &mut cpu.0, &mut cpu.1);
            let got = gpu.run(&p).unwrap();
            compare(&at, &got, &cpu);
            let drawn: Vec<u32> = (0..clusters.len() as u32)
                .filter(|&c| cpu.0[c as usize].instance_count == 1)
                .collect();
            assert_eq!(
                drawn,
                d.cut_from_camera(&cam),
                "{at}: the command line's cut"
            );
            assert_eq!(cpu.1[0], cpu.1[1], "{at}: nothing culled without a frustum");
            let tris: u32 = drawn
                .iter()
                .map(|&c| d.clusters[c as usize].triangle_count)
                .sum();
            assert_eq!(cpu.1[2], tris, "{at}: triangles drawn");
            // Looking at the origin from the eye, a narrow view: what is drawn is in the cut,
            // and what is culled lies outside the frustum.
            let e = Vec3::from_array(eye.map(|x| x as f32));
            let view = Mat4::look_at_rh(e, Vec3::ZERO, Vec3::Y);
            let view = if e.length() < 1e-6 {
                Mat4::look_at_rh(e, Vec3::X, Vec3::Y)
            } else {
                view
            };
            let proj = Mat4::perspective_rh(20f32.to_radians(), 16.0 / 9.0, 0.01, 1000.0);
            let mut p = p;
            p.planes = frustum_planes(proj * view);
            p.cull = 1;
            // And each draw numbered by its cluster and level, as the window's colours read it.
            p.number = 1;
            let mut culled = (vec![CornerDraw::default(); clusters.len()], [0; 4]);
            dag_cut(&p, &clusters, &mut culled.0, &mut culled.1);
            compare(&format!("{at}, culled"), &gpu.run(&p).unwrap(), &culled);
            assert_eq!(
                culled.1[0], cpu.1[0],
                "{at}: the frustum does not change the cut"
            );
            assert!(culled.1[1] <= cpu.1[1], "{at}");
            for (c, (a, b)) in culled.0.iter().zip(&cpu.0).enumerate() {
                assert!(a.instance_count <= b.instance_count, "{at}: cluster {c}");
                let depth = d.clusters[c].depth.min(255);
                assert_eq!(
                    a.first_instance,
                    (depth << 24) | c as u32,
                    "{at}: cluster {c}"
                );
                assert_eq!(b.first_instance, 0, "{at}: unnumbered");
                if a.instance_count < b.instance_count {
                    any_culled = true;
                    let s = d.clusters[c].bounds;
                    let centre = proj * view * Vec3::new(s[0], s[1], s[2]).extend(1.0);
                    let inside = centre.w > 0.0
                        && (centre.x / centre.w).abs() <= 1.0
                        && (centre.y / centre.w).abs() <= 1.0;
                    assert!(!inside, "{at}: cluster {c} culled with its centre in view");
                }
            }
        }
        assert!(any_culled, "{name}: the narrow views culled nothing");
    }
}

/// On screen, from several cameras, the cut at 1 px drawn from the device's draws leaves no
/// hole: no background pixel where the full mesh's render, two pixels in from its silhouette,
/// is covered; far, it draws fewer triangles than the mesh has, and near, not what is out of
/// view.
#[test]
fn a_cut_drawn_from_the_device_has_no_cracks_on_screen() {
    use meshslim::viewer::Model;
    use meshslim::viewer::camera::Camera;
    use meshslim::viewer::dag::DagScene;
    use meshslim::viewer::render::{Renderer, Style, Target};
    let Some(ctx) = gpu_context() else { return };
    let size = (320u32, 240u32);
    for (name, m) in [
        ("noisy_sphere", mesh::noisy_sphere(5, 0.01, 7)),
        ("double_torus", mesh::double_torus(14)),
    ] {
        let (d, _) = dag::build(&m, &DagOptions::default()).unwrap();
        let model = Model::leaves_of(&d, name.into()).unwrap();
        let full = model.original(&ctx.device).unwrap();
        let frame = (model.up.center, model.up.scale);
        let mut scene =
            DagScene::new(&ctx.pipelines, &ctx.queue, &d, frame, model.dag_errors(&d)).unwrap();
        // The cut's heatmap: every vertex of the DAG near the first level.
        let top = scene.scene.max_error;
        assert!(top < 0.05, "{name}: {top}");
        assert!(
            top > 0.0 || name == "double_torus",
            "{name}: the coarse levels moved off it"
        );
        let mut renderer = Renderer::new(&ctx.device, &ctx.queue);
        let style = Style::default();
        let home = model.home_camera(size);
        // A frame of `items` from `cam`, after what `first` records (a cut).
        let render = |renderer: &mut Renderer,
                      first: &mut dyn FnMut(&mut wgpu::CommandEncoder),
                      items: &[(&meshslim::viewer::render::SceneMesh, Mat4)],
                      cam: &Camera| {
            let target = Target::new(&ctx.device, size).unwrap();
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            first(&mut enc);
            renderer.draw(
                &ctx.device,
                &ctx.queue,
                &mut enc,
                &target,
                cam,
                &style,
                items,
            );
            ctx.queue.submit([enc.finish()]);
            target.read_rgba(&ctx.device, &ctx.queue).unwrap()
        };
        let background = render(&mut renderer, &mut |_| {}, &[], &home)[..4].to_vec();
        for (k, (yaw, zoom)) in [(0.35f32, 1.0f32), (2.0, 1.0), (-1.2, 0.45), (0.8, 0.25)]
            .into_iter()
            .enumerate()
        {
            let cam = Camera {
                yaw,
                distance: home.distance * zoom,
                ..home
            };
            let whole = render(&mut renderer, &mut |_| {}, &[(&full, cam.model)], &cam);
            let p = scene.cut_params(&cam, size, 1.0);
            let items = [(&scene.scene, cam.model)];
            let cut = &mut scene.cut;
            let drawn = render(&mut renderer, &mut |enc| cut.record(enc, &p), &items, &cam);
            let (w, h) = (size.0 as i64, size.1 as i64);
            let bg = |img: &[u8], x: i64, y: i64| {
                let i = ((y * w + x) * 4) as usize;
                img[i..i + 4] == background[..]
            };
            let mut inside = 0;
            for y in 2..h - 2 {
                for x in 2..w - 2 {
                    let covered = (-2..=2).all(|dy| (-2..=2).all(|dx| !bg(&whole, x + dx, y + dy)));
                    if covered {
                        inside += 1;
                        assert!(
                            !bg(&drawn, x, y),
                            "{name}, camera {k}: a hole at ({x}, {y}) inside the silhouette"
                        );
                    }
                }
            }
            assert!(
                inside > 1000,
                "{name}, camera {k}: the mesh covers {inside} pixels"
            );
            let counts = meshslim::compute::context::read_back(
                &ctx.device,
                &ctx.queue,
                &scene.cut.counts,
                16,
                "the counts",
            )
            .unwrap();
            let counts: [u32; 4] = bytemuck::pod_read_unaligned(&counts);
            assert!(counts[2] > 0, "{name}, camera {k}: nothing drawn");
            // From the window's first view the far side and the small detail go coarse; from
            // the nearest, part of the surface is out of view and not drawn.
            if k == 0 {
                assert!(
                    (counts[2] as usize) < m.triangles.len(),
                    "{name}, first view: {} of {} triangles",
                    counts[2],
                    m.triangles.len()
                );
            }
            // (The double torus's cut is its root from every one of these views: one cluster.)
            if k == 3 && name == "noisy_sphere" {
                assert!(counts[1] < counts[0], "{name}, nearest view: {counts:?}");
            }
        }
    }
}
