"""What the study scripts share (scripts/study-mug, study-ior, study-orders): the built tools,
bakes made once into a work folder and reused by every study, renders and their comparison.
Python standard library only.
"""
import glob
import hashlib
import json
import os
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def add_arguments(ap, size=384, spp=1):
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default=None, help="bakes, renders, reports (default BUILD/studies)")
    ap.add_argument("--size", type=int, default=size)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--backend", default="egl")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--spp", type=int, default=spp,
                    help="samples per pixel of the reference's colour (its directions: 1)")


class Tools:
    def __init__(self, args, name):
        self.name = name
        self.args = args
        self.exe = {t: os.path.join(args.build, folder, "shrefract-" + t)
                    for t, folder in (("bake", "bake"), ("eval", "eval"), ("render", "eval"))}
        for t, path in self.exe.items():
            if not os.path.exists(path):
                sys.exit("%s: shrefract-%s not built (%s): ninja -C %s shrefract-%s"
                         % (name, t, path, args.build, t))
        self.work = args.work or os.path.join(args.build, "studies")
        for sub in ("bakes", "renders", "reports", "scenes"):
            os.makedirs(os.path.join(self.work, sub), exist_ok=True)
        self.start = time.time()

    def log(self, text):
        print("%s: %s (%.0f s)" % (self.name, text, time.time() - self.start), flush=True)

    def run(self, cmd):
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if p.returncode != 0:
            sys.exit("%s: failed (%d): %s\n%s" % (self.name, p.returncode, " ".join(cmd), p.stdout))
        return p.stdout

    def scene_at_ior(self, scene, ior):
        """A JSON scene with every part at `ior` (for scenes of one glass, e.g. diamond.json),
        written into the work folder with absolute mesh paths."""
        src = os.path.join(ROOT, scene)
        doc = json.load(open(src))
        for part in doc["parts"]:
            part["mesh"] = os.path.join(os.path.dirname(src), part["mesh"])
            part["ior"] = ior
        base = os.path.splitext(os.path.basename(scene))[0]
        out = os.path.join(self.work, "scenes", "%s_ior%g.json" % (base, ior))
        with open(out, "w") as f:
            json.dump(doc, f, indent=1)
        return out

    def wait_for_other_baker(self, out):
        """Another study running at the same time may be baking the same file: wait for that
        shrefract-bake process (found by its -o OUT argument) rather than bake twice."""
        while True:
            pids = []
            for entry in glob.glob("/proc/[0-9]*/cmdline"):
                try:
                    argv = open(entry, "rb").read().split(b"\0")
                except OSError:
                    continue
                if any(a.endswith(b"shrefract-bake") for a in argv[:1]) and out.encode() in argv:
                    pids.append(entry.split("/")[2])
            if not pids:
                return
            self.log("waiting for process %s, which is baking %s" % (pids[0], os.path.basename(out)))
            time.sleep(15)

    @staticmethod
    def own_ior(scene):
        """The index a scene is baked at without --ior: a JSON scene's first part's, else 1.5."""
        if scene.endswith(".json"):
            return json.load(open(os.path.join(ROOT, scene)))["parts"][0]["ior"]
        return 1.5

    def bake_key(self, scene, options, ior):
        """What a bake is made of: the scene file's bytes, the options given, and every default
        the bake tool would fill in (its --help lists them), so that a changed default never
        reuses a stale bake."""
        if not hasattr(self, "_bake_defaults"):
            self._bake_defaults = self.run([self.exe["bake"], "--help"])
        h = hashlib.sha256()
        with open(os.path.join(ROOT, scene), "rb") as f:
            h.update(f.read())
        h.update(json.dumps([scene, list(options), ior, self._bake_defaults]).encode())
        return h.hexdigest()[:10]

    def bake(self, name, scene, options, ior=None):
        """Bakes `scene` (relative to the repository) unless the work folder has it, keyed by
        bake_key. `ior` replaces the index: --ior for a mesh, every part's for a JSON scene."""
        if ior is not None and abs(ior - self.own_ior(scene)) < 1e-9:
            ior = None  # the scene's own index: the plain bake, shared with other studies
        tag = (name if ior is None else "%s_ior%g" % (name, ior)) + "-" + self.bake_key(scene, options, ior)
        out = os.path.join(self.work, "bakes", tag + ".shrefract.exr")
        meta = out + ".json"
        self.wait_for_other_baker(out)
        if os.path.exists(out) and not os.path.exists(meta):
            # Made by an earlier run that stopped before writing its notes (the bake itself is
            # written to a temporary name and renamed only when complete).
            with open(meta, "w") as f:
                json.dump({"scene": scene, "options": options, "ior": ior, "seconds": None}, f)
        if not os.path.exists(out):
            src = os.path.join(ROOT, scene)
            extra = []
            if ior is not None:
                if scene.endswith(".json"):
                    src = self.scene_at_ior(scene, ior)
                else:
                    extra = ["--ior", "%g" % ior]
            t0 = time.time()
            text = self.run([self.exe["bake"], src, "-o", out, "--threads", str(self.args.threads)] +
                            options + extra)
            seconds = time.time() - t0
            with open(meta, "w") as f:
                json.dump({"scene": scene, "options": options, "ior": ior, "seconds": seconds,
                           "summary": text[-2000:]}, f, indent=1)
            self.log("baked %s in %.0f s" % (tag, seconds))
        return out

    def render_key(self, method):
        """What a kept render depends on beyond its tag. The GL methods: the renderer itself (a hash
        of the shrefract-render binary, which holds the runtime and its shaders), so that a changed
        shader or runtime default never reuses a stale image. The ray tracer: its options and their
        defaults (shrefract-render --help), so that the expensive references outlive work on the
        runtime; a change to the reference tracer's code needs an empty work folder."""
        if not hasattr(self, "_render_keys"):
            with open(self.exe["render"], "rb") as f:
                binary = hashlib.sha256(f.read()).hexdigest()[:10]
            options = hashlib.sha256(self.run([self.exe["render"], "--help"]).encode()).hexdigest()[:10]
            self._render_keys = {"gl": binary, "raytrace": options}
        return self._render_keys["raytrace" if method == "raytrace" else "gl"]

    def render(self, bake, tag, camera, env="courtyard", method="sh", extra=(), size=None, reuse=False,
               spp=None):
        """Renders one evaluation buffer; returns its path, ms per frame and GPU memory (MB).
        `env`: a name in data/envmaps or a path. `reuse`: keep a render (and its log) that the
        work folder already has, e.g. a reference, whose tag must then name the bake, camera and
        options it depends on (render_key adds the renderer's part).
        `spp`: the ray tracer's samples per pixel (default: --spp)."""
        size = size or self.args.size
        spp = self.args.spp if spp is None else spp
        out = os.path.join(self.work, "renders", "%s-%s.exr" % (tag, self.render_key(method)))
        log, summary = out + ".log", out + ".json"
        if not (reuse and all(os.path.exists(p) for p in (out, log, summary))):
            envPath = env if os.path.sep in env else os.path.join(ROOT, "data", "envmaps", env + ".exr")
            text = self.run([self.exe["render"], bake, "--env", envPath, "--camera",
                             camera if camera.startswith("orbit:") else "orbit:" + camera,
                             "--size", "%dx%d" % (size, size), "--method", method,
                             "--backend", self.args.backend, "--frames", str(self.args.frames),
                             "--dirs", out, "--json", summary] + list(extra) +
                            (["--spp", str(spp)] if method == "raytrace" and spp > 1 else []))
            with open(log, "w") as f:
                f.write(text)
        with open(summary) as f:
            measured = json.load(f)  # shrefract-render --json: what the render measured
        return {"path": out, "ms": measured["msPerFrame"], "timing": measured["timing"],
                "memoryMB": measured.get("gpuMemoryMB"), "summary": measured}

    def compare(self, ref, test, tag):
        """shrefract-eval image: angular error, coverage, PSNR, SSIM of `test` against `ref`."""
        report = os.path.join(self.work, "reports", tag + ".json")
        self.run([self.exe["eval"], "image", "--ref", ref, "--test", test, "--json", report])
        with open(report) as f:
            return json.load(f)

    def montage(self, inputs, labels, png, errors=False, flip=False):
        """Labelled tiles; rows of angle heat maps (`errors`) and FLIP maps (`flip`) against the
        first input."""
        self.run([self.exe["eval"], "montage"] + list(inputs) + ["--labels"] + list(labels) +
                 (["--errors"] if errors else []) + (["--flip"] if flip else []) + ["--out", png])


def summary(r):
    """The numbers a table shows of one comparison: the exit's angular error, the frame's PSNR and
    SSIM, and the object's own (over the pixels the reference covers: PSNR, SSIM, LDR-FLIP and the
    detail ratio; docs/evaluation.md "Object metrics and FLIP")."""
    a = r["angleDeg"]
    return {"median": a.get("median"), "p95": a.get("p95"), "mean": a.get("mean"),
            "psnr": r["psnr"], "ssim": r["ssim"], "mismatch": r["coverage"]["mismatch"],
            "covered": r["coverage"]["ref"], "objectPsnr": r.get("objectPsnr"),
            "objectSsim": r.get("objectSsim"), "objectFlip": r.get("objectFlip"),
            "detailRatio": r.get("detailRatio")}


def write_section(name, owner, body):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import docsections
    docsections.write_section(os.path.join(ROOT, "docs", "results.md"), name, owner, body)


def write_json(name, doc):
    """docs/NAME.json: every number a study measured, beside docs/results.json."""
    with open(os.path.join(ROOT, "docs", name + ".json"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
