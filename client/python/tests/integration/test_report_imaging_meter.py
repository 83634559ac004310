"""floor-luminance, the camera as an imaging luminance meter (issue 11), on the simulated lab: the camera's luminance
at every grid spot against the simulator's ground truth (within the noise the frame count and the camera's and the
LS-110's noise models give, plus what the flat-field model cannot follow of the optics' true fall-off), the
calibration removing a fall-off of tens of percent; the stored luminances refitted here from the stored spot signals
and readings; the report's agreement, time and Pareto numbers recomputed from the stored rows; the figure shown by
headless Chromium."""
from __future__ import annotations

import json
import re
import socket
import unittest

import numpy as np
import pandas as pd

from daemon_fixture import Daemon
from report_support import check_in_browser, make_report, parse

LEVELS = (100, 25)
ROWS, COLS, FRAMES = 2, 5, 4
RULE_PCT = 2.0  # the report's stated rule: every spot within the LS-110's ±2 %


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


def control(daemon, cmd: dict) -> dict:
    """One command on the simulated lab's control channel (docs/simulator.md)."""
    with socket.socket(socket.AF_UNIX) as s:
        s.connect(daemon.endpoint["simulator_control"])
        s.sendall((json.dumps(cmd) + "\n").encode())
        buf = b""
        while not buf.endswith(b"\n"):
            chunk = s.recv(1 << 20)
            if not chunk:
                break
            buf += chunk
    answer = json.loads(buf)
    assert answer.get("ok"), answer
    return answer


def rho2(px, width, height):
    """ρ² of floor_luminance.hpp: distance from the frame's centre over half its diagonal, squared."""
    cx, cy, r = (width - 1) / 2, (height - 1) / 2, np.hypot(width / 2, height / 2)
    return ((px[0] - cx) ** 2 + (px[1] - cy) ** 2) / r ** 2


def design(signal, r2, terms):
    return np.array([signal * r2 ** k for k in range(terms)])


class ImagingMeter(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = d = Daemon(time_scale=200, seed=11)
        try:
            for instrument in ("ls110", "dmx", "dslr"):
                d.wait_ready(instrument)
            cls.grid = d.run_to_end("cabinet-grid", rows=ROWS, cols=COLS, lamps=["D65"], dimmer_levels=list(LEVELS),
                                    order="lamp-major", settle_s=0)["run_id"]
            # The floor's corners as the bench would measure them on its photograph: the simulator's truth, as
            # fractions of the frame (the DSLR here is 640 × 428, not quite the 3:2 the default corners are for).
            t = control(d, {"cmd": "floor_truth", "instrument": "dslr"})
            cls.size = (t["width"], t["height"])
            corners = []
            for x, y in t["floor_corners_px"]:
                corners += [(x + 0.5) / t["width"], (y + 0.5) / t["height"]]
            cls.floor = d.run_to_end("floor-luminance", rows=ROWS, cols=COLS, lamps=["D65"], dimmer_levels=list(LEVELS),
                                     frames=FRAMES, corners=corners, settle_s=0, grid_run=cls.grid)["run_id"]
            # Truth under each level as the campaign lit it: it ended at its last level; the first is 100 %, which the
            # DMX widget sets exactly (255), so the control channel can set it again.
            cls.truth = {LEVELS[-1]: control(d, {"cmd": "floor_truth", "instrument": "dslr"})}
            control(d, {"cmd": "dimmer", "percent": 100})
            cls.truth[100] = control(d, {"cmd": "floor_truth", "instrument": "dslr"})
            cls.settings = control(d, {"cmd": "truth"})["dslr"]["settings"]
            cls.stored = d.stored_measurements(cls.floor)
            cls.grid_stored = d.stored_measurements(cls.grid)
            cls.path = make_report(d, [cls.grid, cls.floor], "floor-luminance")
            cls.tables, cls.ids = parse(cls.path)
        except BaseException:
            d.cleanup()
            raise

    @classmethod
    def tearDownClass(cls):
        cls.daemon.cleanup()

    def rows(self, prefix):
        return [m for m in self.stored if m["step"].startswith(prefix)]

    def photo(self, level):
        (p,) = self.rows(f"P/D65/D{level:g}")
        return p["data"]

    def test_the_camera_reads_the_true_floor_within_its_noise(self):
        noise = self.truth[100]["noise"]
        gain = noise["gain_dn_per_e_iso100"] * self.settings["iso"] / 100
        for level in LEVELS:
            truth = {(s["row"], s["col"]): s for s in self.truth[level]["spots"]}
            self.assertEqual(self.truth[level]["view"], "chart", "the campaign put the chart back")
            p = self.photo(level)
            spots = {(s["row"], s["col"]): s for s in p["spots"]}

            def rel_noise(s):
                # The spot value's σ over its mean: per pixel the temporal noise (shot, read, ADC) over N frames, the
                # PRNU and the fixed offsets (DSNU, columns), averaged over the spot's pixels.
                S = s["signal"][-1]
                temporal = gain * S + (gain * noise["read_noise_e"]) ** 2 + noise["adc_noise_dn"] ** 2
                var = temporal / FRAMES + (noise["prnu_sigma"] * S) ** 2 + noise["dsnu_sigma_dn"] ** 2 \
                    + noise["column_offset_sigma_dn"] ** 2
                return np.sqrt(var / s["pixels"]) / S

            cal = [(c["row"], c["col"]) for c in p["calibration"]]
            terms = p["degree"] + 1
            # The fit's rows, relative (floor_luminance.hpp), and each calibration reading's relative σ: the LS-110's
            # (the simulator's repeatability at that luminance) and the camera's there.
            a = np.array([design(spots[c]["signal"][-1], rho2(spots[c]["px"], *self.size), terms) / truth[c]["luminance"]
                          for c in cal])
            sig = np.array([np.hypot(truth[c]["ls110_sigma"] / truth[c]["luminance"], rel_noise(spots[c])) for c in cal])
            ata = np.linalg.inv(a.T @ a)
            # What the model cannot follow of the optics, from the truth alone: the flat field fitted to the true
            # relative illumination at the calibration spots, evaluated at each spot.
            ri = {k: truth[k]["relative_illumination"] for k in truth}
            a0 = np.array([design(ri[c], rho2(spots[c]["px"], *self.size), terms) for c in cal])
            c0, *_ = np.linalg.lstsq(a0, np.ones(len(cal)), rcond=None)
            camera = {(m["data"]["row"], m["data"]["col"]): m["value"] for m in self.rows(f"F/D65/D{level:g}/")}
            self.assertEqual(len(camera), ROWS * COLS)
            raw_ratio = []
            for spot, value in camera.items():
                t = truth[spot]
                s = spots[spot]
                u = design(s["signal"][-1], rho2(s["px"], *self.size), terms) / t["luminance"]
                propagated = np.sqrt(u @ ata @ a.T @ np.diag(sig ** 2) @ a @ ata @ u)
                model = design(ri[spot], rho2(s["px"], *self.size), terms) @ c0 - 1
                # 4.5 σ, the model's own error, and 0.05 % for the renderer's bilinear field between its 16-pixel
                # nodes and the field's curvature over the 20 mm disc (both ≤ 0.01 % for this field).
                bound = abs(model) + 4.5 * np.hypot(rel_noise(s), propagated) + 5e-4
                self.assertLess(abs(value / t["luminance"] - 1), bound, f"{level} % spot {spot}")
                # The camera's truth pixel and the campaign's (mapped from the corners) agree.
                self.assertLess(np.hypot(s["px"][0] - t["px"][0], s["px"][1] - t["px"][1]), 0.05, spot)
                raw_ratio.append(s["signal"][-1] / t["luminance"])
            # The optics took a good part of the light towards the floor's edges: the raw signal per cd/m² varies by
            # more than 15 % over the grid, which the calibration removed to within the bounds above.
            self.assertGreater(max(raw_ratio) / min(raw_ratio), 1.15)

    def test_stored_luminances_are_the_flat_field_refitted_here(self):
        for level in LEVELS:
            p = self.photo(level)
            spots = {(s["row"], s["col"]): s for s in p["spots"]}
            readings = {(m["data"]["row"], m["data"]["col"]): m["value"] for m in self.rows(f"C/D65/D{level:g}/")}
            order = [(c["row"], c["col"]) for c in p["calibration"]]
            for k in range(1, len(order) + 1):
                terms = min(2, k - 1) + 1  # the campaign's degree (2), lowered to the spots − 1
                a = np.array([design(spots[c]["signal"][-1], rho2(spots[c]["px"], *self.size), terms) / readings[c]
                              for c in order[:k]])
                coef, *_ = np.linalg.lstsq(a, np.ones(k), rcond=None)
                (variant,) = [v for v in p["variants"] if v["spots"] == k and v["frames"] == FRAMES]
                for i, value in enumerate(variant["luminance"]):
                    s = spots[(i // COLS, i % COLS)]
                    self.assertAlmostEqual(value, design(s["signal"][-1], rho2(s["px"], *self.size), terms) @ coef,
                                           delta=1e-9 * value)
            camera = {(m["data"]["row"], m["data"]["col"]): m["value"] for m in self.rows(f"F/D65/D{level:g}/")}
            full = [v for v in p["variants"] if v["spots"] == len(order) and v["frames"] == FRAMES][0]
            for i, value in enumerate(full["luminance"]):
                self.assertAlmostEqual(camera[(i // COLS, i % COLS)], value, delta=1e-12 * value)

    def test_report_agreement_time_and_pareto(self):
        s = short(self.floor)
        grid = {}
        for m in self.grid_stored:
            g = m["data"]
            grid.setdefault(float(g["dimmer_percent"]), {})[(g["row"], g["col"])] = m["value"]
        doc = self.daemon.client.run(self.grid)
        start = pd.Timestamp(doc["started_at"]).timestamp()
        span = max(pd.Timestamp(m["measured_at"]).timestamp() for m in self.grid_stored) - start
        readings = sum(len(m["data"]["readings"]) for m in self.grid_stored)
        per_grid = span / len(LEVELS)
        t = self.tables[f"{s}-imaging-agreement"]
        settings = {}
        for level in LEVELS:
            p = self.photo(level)
            camera = {(m["data"]["row"], m["data"]["col"]): m["value"] for m in self.rows(f"F/D65/D{level:g}/")}
            d = np.array([100 * (camera[k] - grid[level][k]) / grid[level][k] for k in sorted(camera)])
            key = f"D65-{level:g}"
            self.assertAlmostEqual(t[(key, "mean ΔL/L (%)", "measured")], d.mean(), places=9)
            self.assertAlmostEqual(t[(key, "max |ΔL/L| (%)", "measured")], np.abs(d).max(), places=9)
            self.assertAlmostEqual(t[(key, "RMS ΔL/L (%)", "measured")], np.sqrt((d ** 2).mean()), places=9)
            self.assertAlmostEqual(t[(key, "camera time (s)", "measured")], p["capture_s"] + sum(p["spot_s"]), places=9)
            self.assertAlmostEqual(t[(key, "grid time (s)", "measured")], per_grid, places=6)
            self.assertAlmostEqual(t[(key, "grid time, 80 spots (s)", "measured")], 80 * span / readings, places=6)
            # Against an independent grid the camera meets the stated rule with all its spots and frames.
            self.assertLess(np.abs(d).max(), RULE_PCT)
            for v in p["variants"]:
                dv = np.array([100 * (v["luminance"][i] - grid[level][(i // COLS, i % COLS)]) / grid[level][(i // COLS, i % COLS)]
                               for i in range(ROWS * COLS)])
                e = settings.setdefault((v["spots"], v["frames"]), {"d": [], "t": []})
                e["d"].append(dv)
                e["t"].append(p["capture_s"] * v["frames"] / FRAMES + sum(p["spot_s"][:v["spots"]]))
        pareto = self.tables[f"{s}-pareto-imaging"]
        costs, errors, keys = [], [], sorted(settings)
        for k in keys:
            d = np.concatenate(settings[k]["d"])
            cost = float(np.mean(settings[k]["t"]))
            row = f"k{k[0]}n{k[1]}"
            self.assertAlmostEqual(pareto[(row, "time (s)", "derived")], cost, places=9)
            self.assertAlmostEqual(pareto[(row, "max |ΔL/L| (%)", "derived")], np.abs(d).max(), places=9)
            self.assertAlmostEqual(pareto[(row, "RMS (%)", "derived")], np.sqrt((d ** 2).mean()), places=9)
            costs.append(cost)
            errors.append(float(np.abs(d).max()))
        # One gain for a lens that loses a third of the light at the edges cannot meet the rule; the front and the
        # cheapest setting meeting it, by brute force.
        self.assertGreater(max(e for k, e in zip(keys, errors) if k[0] == 1), RULE_PCT)
        ok = [i for i in range(len(keys)) if errors[i] <= RULE_PCT]
        best = min(ok, key=lambda i: (costs[i], errors[i]))
        for i in range(len(keys)):
            dominated = any((costs[j] <= costs[i] and errors[j] <= errors[i]) and (costs[j] < costs[i] or errors[j] < errors[i])
                            for j in range(len(keys)))
            self.assertEqual(pareto[(f"k{keys[i][0]}n{keys[i][1]}", "Pareto front", "derived")], 0.0 if dominated else 1.0)
        html = self.path.read_text(encoding="utf-8")
        chosen = re.search(r'data-chosen="([^"]*)"', html[html.index(f'id="{s}-pareto-imaging"'):]).group(1)
        self.assertEqual(chosen, f"{keys[best][0]} calibration spot(s), {keys[best][1]} frame(s)")
        check_in_browser(self, self.path, [f"{s}-fig-pareto-imaging"], "floor-luminance")

    def test_dry_run_knows_the_campaign(self):
        r = self.daemon.client.conn.post("/v1/executions", {"campaign": "floor-luminance", "dry_run": True,
                                                            "params": {"rows": 2, "cols": 2, "lamps": ["D65"],
                                                                       "dimmer_levels": [100]}})
        actions = {a["action"]: a for a in r["operator_actions"]}
        self.assertIn("aim_camera", actions)
        self.assertTrue(r["ok"] if "ok" in r else True, r)


if __name__ == "__main__":
    unittest.main()
