"""The dynlab Python module against the CLI: the same grades, the same traces, the same errors.

Run by ctest with Debian's /usr/bin/python3 and PYTHONPATH at the built module (tests/python/
CMakeLists.txt); DYNLAB_BIN is the CLI, DYNLAB_SOURCE_DIR the source tree, DYNLAB_TEST_TMP a scratch folder.
"""
import csv
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

try:
    import dynlab
except ImportError as e:  # the module was not built (no python3-dev / pybind11-dev)
    print(f"DYNLAB_TEST_SKIPPED: the dynlab module is not built ({e})")
    sys.exit(0)

import numpy as np

CLI = os.environ["DYNLAB_BIN"]
SOURCE = os.environ["DYNLAB_SOURCE_DIR"]
TMP = tempfile.mkdtemp(prefix="python_test_", dir=os.environ.get("DYNLAB_TEST_TMP"))


def cli(*args):
    return subprocess.run([CLI, *args], capture_output=True, encoding="utf-8", errors="replace", cwd=TMP)


def examples(lab):
    folder = os.path.join(SOURCE, "labs", lab, "examples")
    return sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".json"))


def write(name, data):
    path = os.path.join(TMP, name)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(data, f)
    return path


class Listing(unittest.TestCase):
    def test_labs_are_the_clis(self):
        names = [line.split()[0] for line in cli("list").stdout.splitlines() if line.strip()]
        self.assertEqual(list(dynlab.labs()), names)
        self.assertGreaterEqual(len(names), 5)

    def test_gains_with_bounds_units_docs(self):
        for name in dynlab.labs():
            lab = dynlab.Lab(name)
            with open(os.path.join(SOURCE, "labs", name, name + ".json"), encoding="utf-8") as f:
                declared = json.load(f)["gains"]
            self.assertEqual(set(lab.gain_info), set(declared))
            for g, d in declared.items():
                info = lab.gain_info[g]
                self.assertEqual((info["value"], info["min"], info["max"]), (d["value"], d["min"], d["max"]))
                self.assertEqual((info["unit"], info["doc"]), (d.get("unit", ""), d.get("doc", "")))
                self.assertEqual(lab.gains[g], d["value"])


class Grades(unittest.TestCase):
    def test_every_lab_grades_as_the_cli(self):
        # One example per lab (the first), graded from its file and from a dict, against results.json.
        for name in dynlab.labs():
            sub = examples(name)[0]
            with self.subTest(lab=name, submission=os.path.basename(sub)):
                out = os.path.join(TMP, "grade_" + name)
                r = cli("grade", sub, "--out", out, "--no-plots")
                self.assertEqual(r.returncode, 0, r.stderr)
                with open(os.path.join(out, "results.json"), encoding="utf-8") as f:
                    expected = json.load(f)
                with open(sub, encoding="utf-8") as f:
                    as_dict = json.load(f)
                for got in (dynlab.grade(sub), dynlab.grade(as_dict, lab=name)):
                    self.assertEqual(got["score"], expected["score"])
                    self.assertEqual([t["score"] for t in got["tests"]], [t["score"] for t in expected["tests"]])
                    self.assertEqual([t["extra_data"].get("value") for t in got["tests"]],
                                     [t["extra_data"].get("value") for t in expected["tests"]])
                    self.assertEqual(got["extra_data"]["fingerprint"]["trajectory_hash"],
                                     expected["extra_data"]["fingerprint"]["trajectory_hash"])
                    self.assertEqual(got["extra_data"]["status"], "graded")

    def test_lab_grade_is_grade_of_its_submission(self):
        lab = dynlab.Lab("slider_crank")
        lab.apply(examples("slider_crank")[0])
        self.assertEqual(lab.grade()["score"], dynlab.grade(examples("slider_crank")[0])["score"])


class Traces(unittest.TestCase):
    def test_trace_and_summary_are_the_clis(self):
        for name in dynlab.labs():
            sub = examples(name)[0]
            with self.subTest(lab=name):
                out = os.path.join(TMP, "run_" + name)
                r = cli("run", name, "--gains", sub, "--duration", "0.3", "--out", out)
                self.assertEqual(r.returncode, 0, r.stderr)
                lab = dynlab.Lab(name)
                lab.set_gains(sub)
                got = lab.run(duration=0.3)
                for engine in ("hand", "bullet"):
                    with open(os.path.join(out, f"trace_{engine}.csv"), encoding="utf-8") as f:
                        rows = list(csv.reader(f))
                    self.assertEqual(list(got["traces"][engine]), rows[0])
                    printed = np.array([[float(x) for x in row] for row in rows[1:]])
                    mine = np.column_stack([got["traces"][engine][c] for c in rows[0]])
                    self.assertEqual(mine.shape, printed.shape)
                    self.assertTrue(np.array_equal(mine, printed), f"{engine} trace differs from the CSV")
                with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
                    summary = json.load(f)
                for key in ("engines", "agreement", "units", "status", "dt", "duration"):
                    self.assertEqual(got.get(key), summary.get(key), key)

    def test_two_labs_do_not_interfere(self):
        a, b = dynlab.Lab("slider_crank"), dynlab.Lab("pen_on_table")
        first = a.run(engine="hand", duration=0.2)
        b.set_gains({g: v for g, v in b.gains.items()})
        b.run(engine="hand", duration=0.2)
        a2 = dynlab.Lab("slider_crank")
        a2.set_gains(**{g: info["max"] for g, info in a2.gain_info.items()})
        a2.run(engine="hand", duration=0.2)
        again = a.run(engine="hand", duration=0.2)
        self.assertEqual(first["engines"]["hand"]["trace_hash"], again["engines"]["hand"]["trace_hash"])

    def test_gil_released_during_a_run(self):
        # A thread counts while the main thread runs the lab: with the GIL held for the whole run
        # it could not count at all during it.
        lab = dynlab.Lab("slider_crank")
        count = [0]
        stop = threading.Event()

        def counter():
            while not stop.is_set():
                count[0] += 1
        t = threading.Thread(target=counter)
        t.start()
        time.sleep(0.02)
        before = count[0]
        start = time.perf_counter()
        lab.run(engine="both", duration=5.0)
        elapsed = time.perf_counter() - start
        during = count[0] - before
        stop.set()
        t.join()
        self.assertGreater(elapsed, 0.05)
        self.assertGreater(during, 1000, f"the counting thread ran {during} times in {elapsed:.2f} s")

    def test_ctrl_c_stops_a_run(self):
        lab = dynlab.Lab("slider_crank")
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        start = time.perf_counter()
        timer.start()
        with self.assertRaises(KeyboardInterrupt):
            lab.run(engine="both", duration=300)
        self.assertLess(time.perf_counter() - start, 10)
        self.assertEqual(lab.run(engine="hand", duration=0.1)["status"], "ok")  # still usable


class Pictures(unittest.TestCase):
    def test_frame_is_the_clis_frame(self):
        # dynlab run --frames writes frame k at t = k/30 s; frame(k/30) is that image, pixel for pixel.
        import matplotlib.image
        out = os.path.join(TMP, "frames_slider_crank")
        r = cli("run", "slider_crank", "--duration", "0.2", "--frames", "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        lab = dynlab.Lab("slider_crank")
        lab.run(duration=0.2)
        for k in (0, 5):
            with self.subTest(frame=k):
                png = matplotlib.image.imread(os.path.join(out, "frames", f"{k:05d}.png"))
                expected = np.rint(png[:, :, :3] * 255).astype(np.uint8)
                got = lab.frame(k / 30)
                self.assertEqual(got.shape, (480, 640, 3))
                self.assertEqual(got.dtype, np.uint8)
                self.assertTrue(np.array_equal(got, expected), f"frame {k} differs from the CLI's")
        self.assertFalse(np.array_equal(lab.frame(0.0), lab.frame(0.15)))  # the mechanism moved
        small = lab.frame(0.1, width=320, height=240, overlay=False)
        self.assertEqual(small.shape, (240, 320, 3))

    def test_video_is_written_whole(self):
        lab = dynlab.Lab("pen_on_table")
        with self.assertRaises(dynlab.InputError) as e:
            lab.frame(0.0)  # nothing run yet
        self.assertIn("run first", str(e.exception))
        lab.run(engine="hand", duration=0.3)
        path = lab.video(os.path.join(TMP, "pen.mp4"))
        self.assertEqual(path, os.path.abspath(os.path.join(TMP, "pen.mp4")))
        with open(path, "rb") as f:
            head = f.read(12)
        self.assertEqual(head[4:8], b"ftyp")
        self.assertGreater(os.path.getsize(path), 1000)
        self.assertEqual([n for n in os.listdir(TMP) if n.startswith(".dynlab-video")], [])
        for kwargs in ({"engine": "bullet"}, {"width": 641}, {"width": 10}):
            with self.subTest(**kwargs), self.assertRaises(dynlab.InputError):
                lab.video(os.path.join(TMP, "bad.mp4"), **kwargs)
        with self.assertRaises(dynlab.InputError):
            lab.video(os.path.join(TMP, "no_such_folder", "x.mp4"))
        with self.assertRaises(dynlab.InputError):
            lab.frame(-1.0)
        self.assertFalse(os.path.exists(os.path.join(TMP, "bad.mp4")))


class Errors(unittest.TestCase):
    def cli_error(self, lab, gains):
        path = write("bad_gains.json", gains)
        r = cli("run", lab, "--gains", path, "--duration", "0.01", "--out", os.path.join(TMP, "bad"))
        self.assertEqual(r.returncode, 2)
        line = r.stderr.strip()
        self.assertTrue(line.startswith("error: "), line)
        return path, line[len("error: "):]

    def test_bad_gains_raise_the_clis_message(self):
        lab = dynlab.Lab("slider_crank")
        name, info = next(iter(lab.gain_info.items()))
        before = lab.gains
        # 2**80: an int past 64 bits is read as the CLI reads it from the file (a double), not "Unable to cast".
        for gains in ({"no_such_gain": 1.0}, {name: info["max"] * 10 + 1}, {name: "fast"}, {name: [1]}, {name: 2**80},
                      {name: -2**80}, {name: 2**64 - 1}):
            with self.subTest(gains=gains):
                path, message = self.cli_error("slider_crank", {"gains": gains})
                with self.assertRaises(dynlab.InputError) as e:
                    lab.set_gains(path)
                self.assertEqual(str(e.exception), message)
                with self.assertRaises(dynlab.InputError) as e:
                    lab.set_gains(gains)
                self.assertEqual(str(e.exception), message.replace(path, "<gains>", 1))
                self.assertTrue(e.exception.path.startswith("/gains/"))
                self.assertIsInstance(e.exception, ValueError)
                self.assertEqual(lab.gains, before)  # nothing changed

    def test_bad_submission_raises_the_grade_message(self):
        path = write("bad_sub.json", {"lab": "slider_crank", "gains": {"kp_x": -5}})
        r = cli("grade", path, "--out", os.path.join(TMP, "bad_grade"), "--no-plots")
        self.assertEqual(r.returncode, 2)
        message = r.stderr.strip().splitlines()[0][len("error: "):]
        with self.assertRaises(dynlab.InputError) as e:
            dynlab.grade(path)
        self.assertEqual(str(e.exception), message)

    def test_unknown_lab_and_bad_arguments(self):
        with self.assertRaises(dynlab.InputError) as e:
            dynlab.Lab("no_such_lab")
        self.assertIn("unknown lab", str(e.exception))
        lab = dynlab.Lab("slider_crank")
        for kwargs in ({"engine": "fast"}, {"duration": -1.0}, {"duration": 1e-9}):
            with self.subTest(**kwargs), self.assertRaises(dynlab.InputError):
                lab.run(**kwargs)
        with self.assertRaises(TypeError):
            lab.set_gains({"kp_x": {1, 2}})
        # Past the steps a run may take: refused at the argument, with the bound named, before any work.
        with self.assertRaises(dynlab.InputError) as e:
            lab.run(duration=3000)
        self.assertIn("duration", str(e.exception))
        self.assertIn("more than the 2e+06 a run may take", str(e.exception))
        self.assertNotIn("slider_crank.json", str(e.exception))


def python(code):
    """Runs code in a fresh interpreter, so that a crash fails the test instead of this process."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, encoding="utf-8", errors="replace", cwd=TMP,
                          timeout=900)


class Students(unittest.TestCase):
    """A plant per student: Lab(student=) and grade(student=) are the CLI's --student."""

    SUB = {"lab": "fivebar", "kind": "task_inverse_dynamics", "gains": {"kp": 2000, "kd": 40, "omega_n": 30, "zeta": 0.7}}

    def setUp(self):
        os.environ["DYNLAB_COURSE_SECRET"] = "python-test-secret"

    def tearDown(self):
        os.environ.pop("DYNLAB_COURSE_SECRET", None)

    def test_grade_on_a_students_plant_is_the_clis(self):
        path = write("student_sub.json", self.SUB)
        out = os.path.join(TMP, "student_grade")
        env = dict(os.environ)
        r = subprocess.run([CLI, "grade", path, "--student", "alice", "--no-plots", "--out", out], capture_output=True,
                           encoding="utf-8", errors="replace", cwd=TMP, env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "results.json"), encoding="utf-8") as f:
            cli_results = json.load(f)
        mine = dynlab.grade(self.SUB, student="alice")
        self.assertEqual(mine["score"], cli_results["score"])
        self.assertEqual(mine["extra_data"]["plant"], cli_results["extra_data"]["plant"])
        lab = dynlab.Lab("fivebar", student="alice")
        self.assertEqual(lab.student, "alice")
        lab.apply(self.SUB)
        self.assertEqual(lab.grade()["score"], cli_results["score"])

    def test_no_key_or_a_bad_id_raises(self):
        os.environ.pop("DYNLAB_COURSE_SECRET", None)
        with self.assertRaises(dynlab.InputError) as e:
            dynlab.Lab("fivebar", student="alice")
        self.assertIn("<python>: student: expected DYNLAB_STUDENT_KEY", str(e.exception))
        os.environ["DYNLAB_COURSE_SECRET"] = "x"
        with self.assertRaises(dynlab.InputError) as e:
            dynlab.grade(self.SUB, student="a b")
        self.assertIn("student: expected a student ID", str(e.exception))


class Hostile(unittest.TestCase):
    """Python input as hostile as a file: never a crash, always the CLI's checks as ValueError or TypeError."""

    def test_self_referencing_data_is_a_value_error(self):
        r = python("""
import dynlab
lab = dynlab.Lab("slider_crank")
g = {}
g["kp_x"] = g
s = {"lab": "slider_crank"}
s["gains"] = s
l = []
l.append(l)
for call in (lambda: lab.set_gains(g), lambda: lab.apply(s), lambda: dynlab.grade(s), lambda: lab.set_gains(kp_x=l)):
    try:
        call()
        print("no error")
    except ValueError as e:
        print("ValueError", str(e)[-50:])
""")
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])  # today: SIGSEGV (-11)
        lines = r.stdout.splitlines()
        self.assertEqual(len(lines), 4, r.stdout)
        for line in lines:
            self.assertTrue(line.startswith("ValueError "), line)
            self.assertTrue(line.endswith("expected JSON nested at most 64 levels deep"), line)

    def test_one_lab_from_two_threads(self):
        # One thread draws the last run (video and frames) while the other replaces it with new runs.
        r = python(f"""
import os, threading, dynlab
lab = dynlab.Lab("slider_crank")
lab.run(engine="both", duration=0.4)
failed = []
def guard(f):
    def body():
        try:
            f()
        except Exception as e:
            failed.append(repr(e))
    return body
def draw():
    for i in range(3):
        lab.video(os.path.join({TMP!r}, f"thread_{{i}}.mp4"))
        lab.frame(0.3)
def run():
    for i in range(8):
        lab.run(engine="both", duration=0.4)
        lab.set_gains(kp_x=100 + i)
threads = [threading.Thread(target=guard(f)) for f in (draw, run, draw)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print("failed:", failed)
""")
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])  # today: SIGSEGV every time
        self.assertEqual(r.stdout.strip(), "failed: []")

    def test_time_budget_is_checked_like_the_clis(self):
        sub = examples("slider_crank")[0]
        lab = dynlab.Lab("slider_crank")
        for value, text in ((float("nan"), "nan"), (-1.0, "-1"), (0.0, "0"), (float("inf"), "inf"), (1e300, "1e300"),
                            (86400.5, "86400.5")):
            with self.subTest(time_budget=value):
                with self.assertRaises(dynlab.InputError) as e:  # today: graded, 1/15 marked out_of_time
                    dynlab.grade(sub, time_budget=value)
                self.assertIsInstance(e.exception, ValueError)
                self.assertEqual(e.exception.path, "time_budget")
                with self.assertRaises(dynlab.InputError):
                    lab.grade(time_budget=value)
                r = cli("grade", sub, "--time-budget=" + text, "--out", os.path.join(TMP, "budget"))
                self.assertEqual(r.returncode, 2)
                self.assertIn("--time-budget: " + e.exception.expected, r.stderr)
        with self.assertRaises(TypeError):
            dynlab.grade(sub, time_budget="10")

    def test_numbers_and_text_no_json_holds(self):
        lab = dynlab.Lab("slider_crank")
        for gains in ({"kp_x": 10**400}, {"kp_x": -(10**400)}, {"kp_x": "\ud800"}, {"\udcff": 1.0}):
            with self.subTest(gains=repr(gains)), self.assertRaises(ValueError) as e:  # today: RuntimeError / OverflowError
                lab.set_gains(gains)
            self.assertNotIsInstance(e.exception, RuntimeError)
        with self.assertRaises(dynlab.InputError) as e:
            lab.set_gains(kp_x=2**80)  # keywords too
        self.assertIn("/gains/kp_x: expected a number in [", str(e.exception))
        self.assertIn("got 1.2089258196146292e+24", str(e.exception))
        with self.assertRaises(dynlab.InputError) as e:  # more data than a submission file may hold, refused as it is read
            lab.set_gains({"kp_x": ["x" * 1000] * 2000})
        self.assertIn("expected at most 1048576 bytes of JSON data", str(e.exception))
        with open(os.path.join(TMP, "gains.json"), "w", encoding="utf-8") as f:
            json.dump({"gains": {"kp_x": 100}}, f)
        with self.assertRaises(dynlab.InputError) as e:  # not gains.json: open() would stop at the NUL
            lab.set_gains(os.path.join(TMP, "gains.json\0.txt"))
        self.assertIn("expected a path without a NUL byte", str(e.exception))


class LabsOutsideTheTree(unittest.TestCase):
    """labs= (the CLI's --labs DIR) and DYNLAB_LABS: a lab in a folder outside the tree, found after the tree's.
    Each case runs in a fresh interpreter: a folder once used stays registered in the process."""

    def setUp(self):
        self.folder = os.path.join(TMP, "course_labs")
        if not os.path.isdir(os.path.join(self.folder, "pylab")):
            os.makedirs(self.folder, exist_ok=True)
            r = cli("new-lab", "pylab", "--from", "fivebar", "--labs", self.folder)
            self.assertEqual(r.returncode, 0, r.stderr)

    def test_labs_argument(self):
        r = python(f"""
import os, dynlab
try:
    dynlab.Lab("pylab")
    print("found without labs=")
except dynlab.InputError as e:
    print("unknown" if "unknown lab" in str(e) else str(e))
held = [dynlab.Lab(name) for name in dynlab.labs()]  # each holds its lab's registry entry while labs are added
lab = dynlab.Lab("pylab", labs={self.folder!r})
print(lab.name, os.path.dirname(lab.config) == os.path.join({self.folder!r}, "pylab"))
for other in held:
    assert other.run(engine="hand", duration=0.01)["status"] == "ok", other.name
names = dynlab.labs()
print("pylab" in names, "fivebar" in names, "slider_crank" in names)
print(lab.run(engine="hand", duration=0.05)["status"])
""")
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        self.assertEqual(r.stdout.splitlines(), ["unknown", "pylab True", "True True True", "ok"])

    def test_environment_and_list_and_refusals(self):
        env = dict(os.environ, DYNLAB_LABS=self.folder)
        r = subprocess.run([sys.executable, "-c", "import dynlab; print(dynlab.Lab('pylab').name)"], capture_output=True,
                           encoding="utf-8", errors="replace", cwd=TMP, env=env, timeout=900)
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        self.assertEqual(r.stdout.strip(), "pylab")
        clash = os.path.join(TMP, "clash_labs")
        if not os.path.isdir(clash):
            import shutil
            shutil.copytree(os.path.join(SOURCE, "labs", "fivebar"), os.path.join(clash, "fivebar"))
        r = python(f"""
import dynlab
print("pylab" in dynlab.labs(labs=[{self.folder!r}]))
for labs in ({clash!r}, {os.path.join(TMP, "no_such_folder")!r}):
    try:
        dynlab.Lab("fivebar", labs=labs)
        print("no error")
    except dynlab.InputError as e:
        print(e.file, e.path, "fivebar" in e.expected or "existing folder" in e.expected)
try:
    dynlab.labs(labs=5)
except TypeError as e:
    print("TypeError")
""")
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        self.assertEqual(r.stdout.splitlines(), ["True", "<python> labs True", "<python> labs True", "TypeError"])


if __name__ == "__main__":
    unittest.main(verbosity=2)
