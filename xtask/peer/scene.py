"""cargo xtask peer --scene FILE.xml: one Mitsuba scene file rendered by Mitsuba 3
(scalar_spectral) and by Spectrace (`spectrace render FILE.xml`), compared in region means
(8x8-pixel blocks of linear sRGB), and against the Tungsten reference render
(TungstenRender.exr) when one lies beside the file. Method: docs/import.md."""
import argparse, json, os, re, subprocess, sys, time
import numpy as np
import mitsuba as mi


def arguments():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--spectrace", required=True)
    p.add_argument("--root", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--scene", required=True, action="append", help="a Mitsuba XML scene (repeatable)")
    p.add_argument("--spp", type=int, default=256, help="samples per pixel for both renderers")
    p.add_argument("-D", dest="defines", action="append", default=[], help="NAME=VALUE for both")
    p.add_argument("--threads", type=int, default=0)
    return p.parse_args()


def blocks(img, k=8):
    h, w = img.shape[0] // k * k, img.shape[1] // k * k
    return img[:h, :w].reshape(h // k, k, w // k, k, -1).mean(axis=(1, 3))


def luminance(rgb):
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def compare(a, b):
    """Region means of image a against b: overall mean ratio per channel, and the median and
    95th percentile of |a/b - 1| over 8x8 blocks of luminance (blocks above 5% of the mean)."""
    ba, bb = blocks(a), blocks(b)
    la, lb = luminance(ba), luminance(bb)
    keep = lb > 0.05 * lb.mean()
    rel = np.abs(la[keep] / lb[keep] - 1.0)
    return {
        "mean_ratio_rgb": [float(a[..., c].mean() / b[..., c].mean()) for c in range(3)],
        "block_median": float(np.median(rel)),
        "block_p95": float(np.percentile(rel, 95)),
        "blocks": int(keep.sum()),
    }


def mitsuba_render(path, defines, spp, seed):
    mi.set_variant("scalar_spectral")
    try:
        scene = mi.load_file(path, **defines)
    except RuntimeError as e:
        # Mitsuba refuses definitions the file does not use: drop those (Spectrace ignores them).
        unused = set(re.findall(r"\$(\w+)=", str(e)))
        if not unused:
            raise
        scene = mi.load_file(path, **{k: v for k, v in defines.items() if k not in unused})
    t = time.perf_counter()
    img = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)[..., :3]
    return img, time.perf_counter() - t


def spectrace_render(args, path, out, seed):
    cmd = [args.spectrace, "render", path, "--spp", str(args.spp), "--seed", str(seed), "--out", out,
           "--quiet", "--integrator", "path", "--threads", str(args.threads)]
    for d in args.defines:
        cmd += ["-D", d]
    t = time.perf_counter()
    subprocess.run(cmd, check=True)
    wall = time.perf_counter() - t
    name = os.path.splitext(os.path.basename(path))[0]
    side = json.load(open(os.path.join(out, name + ".json")))
    img = np.array(mi.Bitmap(os.path.join(out, name + ".exr")), dtype=np.float64)[..., :3]
    img *= 2.0 ** -int(side.get("exr_scale_log2", 0))
    return img, wall


def main():
    args = arguments()
    defines = dict(d.split("=", 1) for d in args.defines)
    defines_mi = dict(defines, spp=str(args.spp))
    os.makedirs(args.work, exist_ok=True)
    rows = []
    for path in args.scene:
        path = os.path.abspath(path)
        name = os.path.basename(os.path.dirname(path)) + "/" + os.path.basename(path)
        mi_img, mi_s = mitsuba_render(path, {k: v for k, v in defines_mi.items() if k != "spp"}, args.spp, 1)
        mi_img2, _ = mitsuba_render(path, {k: v for k, v in defines_mi.items() if k != "spp"}, args.spp, 2)
        out = os.path.join(args.work, name.replace("/", "_"))
        st_img, st_s = spectrace_render(args, path, out, 1)
        row = {"scene": name, "spp": args.spp, "size": list(st_img.shape[:2]),
               "mitsuba_seconds": mi_s, "spectrace_seconds": st_s,
               "spectrace_vs_mitsuba": compare(st_img, (mi_img + mi_img2) / 2),
               "mitsuba_vs_mitsuba": compare(mi_img, mi_img2)}
        ref = os.path.join(os.path.dirname(path), "TungstenRender.exr")
        if os.path.exists(ref):
            r = np.array(mi.Bitmap(ref), dtype=np.float64)[..., :3]
            f = r.shape[0] // st_img.shape[0]
            if f >= 1 and r.shape[0] == f * st_img.shape[0] and r.shape[1] == f * st_img.shape[1]:
                r = r.reshape(st_img.shape[0], f, st_img.shape[1], f, 3).mean(axis=(1, 3))
                row["spectrace_vs_tungsten"] = compare(st_img, r)
                row["mitsuba_vs_tungsten"] = compare((mi_img + mi_img2) / 2, r)
        rows.append(row)
        print(json.dumps(row), flush=True)
    with open(os.path.join(args.work, "results.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print("| scene | vs | mean ratio R, G, B | blocks: median, 95th pct of abs(ratio - 1) |")
    print("|---|---|---|---|")
    for row in rows:
        for key in ["spectrace_vs_mitsuba", "mitsuba_vs_mitsuba", "spectrace_vs_tungsten", "mitsuba_vs_tungsten"]:
            if key in row:
                c = row[key]
                print(f"| {row['scene']} | {key.replace('_', ' ')} | {', '.join(f'{x:.4f}' for x in c['mean_ratio_rgb'])} | "
                      f"{100 * c['block_median']:.2f}%, {100 * c['block_p95']:.2f}% ({c['blocks']} blocks) |")


if __name__ == "__main__":
    sys.exit(main())
