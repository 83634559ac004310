"""Client.verify: the command line it runs (the daemon it talks to, the key kept off the command line, the scale
and --store passed on), the verdict returned with its comparisons as a DataFrame for exit 0 and 4, and exit 1 and 2
raised as VerifyFailed with colorlab's own message. The binary is a stand-in script (COLORLAB_BIN); the real
comparison end to end is tests/verify/cli (ctest verify_cli_test)."""
import json
import os
import stat
import tempfile
import unittest
from pathlib import Path

import numpy as np

import colorlab

RESULT = {"summary": {"verdict": "differs", "kinds": {}, "scales": [{"kind": "light_spot", "how": "given", "factor": 1}]},
          "comparisons": [{"kind": "light_spot", "where": "r0c0", "difference": 0.1, "expanded": 0.02,
                           "verdict": "differs", "budget": {"lamp drift": 0.006}},
                          {"kind": "light_floor", "where": "r0c0", "difference": 0.001, "expanded": 0.02,
                           "verdict": "agrees", "budget": {"floor map": 0.008}}],
          "floor_difference": [[0.001]], "exit_status": 4}


class VerifyTest(unittest.TestCase):
    def setUp(self):
        self.dir = Path(self.enterContext(tempfile.TemporaryDirectory()))
        self.args = self.dir / "args.json"
        self.old = os.environ.get("COLORLAB_BIN")
        self.addCleanup(self.restore)

    def restore(self):
        if self.old is None:
            os.environ.pop("COLORLAB_BIN", None)
        else:
            os.environ["COLORLAB_BIN"] = self.old

    def fake(self, code: int, out: str = "", err: str = ""):
        script = self.dir / "colorlab"
        script.write_text(
            "#!/usr/bin/python3\nimport json, os, sys\n"
            f"json.dump({{'argv': sys.argv[1:], 'key': os.environ.get('COLORLAB_API_KEY')}}, open({str(self.args)!r}, 'w'))\n"
            f"sys.stdout.write({out!r}); sys.stderr.write({err!r}); sys.exit({code})\n")
        script.chmod(script.stat().st_mode | stat.S_IXUSR)
        os.environ["COLORLAB_BIN"] = str(script)

    def called(self):
        return json.loads(self.args.read_text())

    def test_the_verdict_and_its_table(self):
        self.fake(4, json.dumps(RESULT))
        lab = colorlab.Client(socket="/run/colorlab.sock")
        r = lab.verify("box.exr", against=["a1", {"id": "b2"}], scale=1, store=True)
        self.assertEqual(r["summary"]["verdict"], "differs")
        self.assertEqual(r["exit_status"], 4)
        self.assertEqual(list(r["table"]["verdict"]), ["differs", "agrees"])
        self.assertEqual(list(r["table"]["where"]), ["r0c0", "r0c0"])
        self.assertEqual(self.called()["argv"], ["--socket", "/run/colorlab.sock", "verify", "box.exr", "--against",
                                                 "a1", "b2", "--json", "--scale", "1.0", "--store"])

    def test_agrees_over_tcp_with_the_key_in_the_environment(self):
        self.fake(0, json.dumps({**RESULT, "exit_status": 0}))
        lab = colorlab.Client("http://lab:8765", key="clk_secret")
        r = lab.verify(Path("box.exr"), against=["a1"])
        self.assertEqual(r["exit_status"], 0)
        called = self.called()
        self.assertEqual(called["argv"][:2], ["--url", "http://lab:8765"])
        self.assertNotIn("clk_secret", " ".join(called["argv"]))
        self.assertEqual(called["key"], "clk_secret")
        self.assertNotIn("--scale", called["argv"])
        self.assertNotIn("--lens-calibration", called["argv"])
        lab.verify("box.exr", against=["a1"], lens_calibration="EOS 20D / EF 50mm")
        self.assertEqual(self.called()["argv"][-2:], ["--lens-calibration", "EOS 20D / EF 50mm"])

    def test_the_rendering_noise_options_passed_on(self):
        self.fake(0, json.dumps({**RESULT, "exit_status": 0}))
        lab = colorlab.Client(socket="/s")
        lab.verify("box.exr", against=["a1"])
        self.assertNotIn("--no-rendering-noise", self.called()["argv"])
        self.assertNotIn("--noise-neighbours", self.called()["argv"])
        lab.verify("box.exr", against=["a1"], rendering_noise=False, store=True)
        self.assertEqual(self.called()["argv"][-2:], ["--no-rendering-noise", "--store"])
        lab.verify("box.exr", against=["a1"], noise_neighbours=4)
        self.assertEqual(self.called()["argv"][-2:], ["--noise-neighbours", "4"])
        # JSON's one number type: a whole-valued float is that whole number, passed on as an integer.
        lab.verify("box.exr", against=["a1"], noise_neighbours=8.0)
        self.assertEqual(self.called()["argv"][-2:], ["--noise-neighbours", "8"])
        # numpy's numbers (a value read from a DataFrame) are numbers too.
        lab.verify("box.exr", against=["a1"], noise_neighbours=np.int64(6))
        self.assertEqual(self.called()["argv"][-2:], ["--noise-neighbours", "6"])
        lab.verify("box.exr", against=["a1"], noise_neighbours=np.float64(5.0))
        self.assertEqual(self.called()["argv"][-2:], ["--noise-neighbours", "5"])
        # Not a whole number >= 1: refused here, before colorlab is run (the binary records its argv when it is).
        self.args.unlink()
        for bad, error in ((0, ValueError), (-3, ValueError), (2.5, ValueError), (0.0, ValueError), (-8.0, ValueError),
                           (float("nan"), ValueError), (float("inf"), ValueError), (1e300, ValueError), (np.float64(2.5), ValueError),
                           (np.int64(0), ValueError),
                           ("8", TypeError), ("8.0", TypeError), (True, TypeError), ([8], TypeError)):
            with self.assertRaises(error):
                lab.verify("box.exr", against=["a1"], noise_neighbours=bad)
        with self.assertRaises(ValueError):
            lab.verify("box.exr", against=["a1"], noise_neighbours=2**31)
        # None or 0 would silently leave the noise out (narrower bands), "false" silently keep it.
        for bad in (None, 0, 1, "false", "no"):
            with self.assertRaises(TypeError):
                lab.verify("box.exr", against=["a1"], rendering_noise=bad)
        self.assertFalse(self.args.exists())

    def test_no_verdict_raises_with_colorlabs_message(self):
        for code, err in ((1, "colorlab: bad.exr: not an image\n  hint: …\n"), (2, "colorlab: 404 Not Found: no run 'x'\n")):
            self.fake(code, "", err)
            with self.assertRaises(colorlab.VerifyFailed) as e:
                colorlab.Client(socket="/s").verify("bad.exr", against=["x"])
            self.assertEqual(e.exception.exit_status, code)
            self.assertIn(err.split(": ", 1)[1].splitlines()[0], str(e.exception))
        with self.assertRaises(ValueError):
            colorlab.Client(socket="/s").verify("a.exr", against=[])


if __name__ == "__main__":
    unittest.main()
