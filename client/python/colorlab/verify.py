"""A rendering verified against the measured scene (issue 23, docs/verify.md "Using it"): ``Client.verify``.

The comparison engine is C++ (verify/compare) and reads the rendering file where it is, so this runs
``colorlab verify … --json`` against the same daemon (binary found as ``colorlab analyze`` is: ``COLORLAB_BIN``,
``COLORLAB_BIN_DIR``, beside the installation or the source tree, then PATH) and returns its document.
"""
from __future__ import annotations

import json
import math
import numbers
import os
import subprocess
from typing import Sequence

import pandas as pd

from .errors import ColorlabError
from .runs import run_id

TIMEOUT_S = 300
EXIT_AGREES, EXIT_DIFFERS = 0, 4


class VerifyFailed(ColorlabError):
    """The verification could not be made: ``exit_status`` 1 (a local error: the file, the runs' content, an
    option) or 2 (the daemon refused); ``message`` is colorlab's own, with its hint."""

    def __init__(self, exit_status: int, message: str):
        super().__init__(f"colorlab verify exited {exit_status}: {message}")
        self.exit_status = exit_status
        self.message = message


class VerifyMixin:
    def verify(self, path: str | os.PathLike, against: Sequence, scale: float | None = None, *, store: bool = False,
               lamp: str | None = None, dimmer: float | None = None, lens_calibration: str | None = None,
               rendering_noise: bool = True, noise_neighbours: int | None = None) -> dict:
        """``colorlab verify PATH --against RUN… --json``: the rendering beside the runs' measured scene.

        Returns the result document — ``summary`` (``verdict`` "agrees"/"differs", per kind compared/agree/differ,
        ``scales`` given or fitted), ``comparisons``, ``floor_difference``, ``exit_status`` (0 agrees, 4 differs),
        ``stored_run`` with ``store=True``, ``colour`` and ``not_compared`` when a characterize-camera run is among
        ``against``, ``placement`` (how the floor was placed: through the lab's lens calibration for the floor
        photograph's size, ``lens_calibration`` naming one among several, or as a pinhole) — plus ``table``: the comparisons as a DataFrame (kind, where,
        difference, expanded, verdict, …). ``scale``: renderer unit → cd/m² (omitted: one factor fitted per kind,
        which cannot see a uniformly wrong level). ``rendering_noise=False`` leaves the rendering's own Monte-Carlo
        noise out of the budget (only for a renderer that states its image is exact); ``noise_neighbours``: the
        regions its level is pooled over (a whole number ≥ 1, 8.0 as 8; colorlab's default 8); both are in the result and a stored
        verification's params. Raises ``VerifyFailed`` when no verdict could be made, ``TypeError``/``ValueError``
        for a ``rendering_noise`` that is not a bool or a ``noise_neighbours`` that is not a whole number ≥ 1
        (``TypeError`` for a non-number, ``ValueError`` for 2.5, NaN, ∞, 0 or less)."""
        from .report.analyze import colorlab_binary  # the one place that knows where the binary is

        if not isinstance(rendering_noise, bool):  # None or 0 would silently narrow every band, "false" keep it
            raise TypeError(f"rendering_noise must be True or False, not {type(rendering_noise).__name__}")
        if noise_neighbours is not None:
            # numbers.Integral / Real: numpy's int64 (a DataFrame's column) and float64 are numbers too.
            if isinstance(noise_neighbours, bool) or not isinstance(noise_neighbours, numbers.Real):
                raise TypeError(f"noise_neighbours must be a whole number, not {type(noise_neighbours).__name__}")
            if isinstance(noise_neighbours, numbers.Integral):
                noise_neighbours = int(noise_neighbours)
            else:
                # One number type in JSON: 8.0 (from a config, a JSON body, a JS caller) is the whole number 8.
                value = float(noise_neighbours)
                if not math.isfinite(value) or not value.is_integer():
                    raise ValueError(f"noise_neighbours must be a whole number (got {noise_neighbours!r})")
                noise_neighbours = int(value)
            if noise_neighbours < 1:
                raise ValueError(f"noise_neighbours must be at least 1 (got {noise_neighbours}): the rendering's noise "
                                 "is pooled over that many nearest regions; rendering_noise=False leaves it out")
            if noise_neighbours > 2**31 - 1:  # the CLI's int: beyond it colorlab could not parse the option
                raise ValueError(f"noise_neighbours must be at most {2**31 - 1} (got {noise_neighbours})")
        runs = [run_id(r) for r in against]
        if not runs:
            raise ValueError("against: give at least one run (a floor-luminance run, optionally a cabinet-grid run; "
                             "a characterize-camera run for the colour)")
        cmd = [str(colorlab_binary())]
        env = dict(os.environ, LC_ALL="C")
        if self.conn.socket is not None:
            cmd += ["--socket", self.conn.socket]
        else:
            cmd += ["--url", self.conn.url]
            if self.conn.verify:
                cmd += ["--cacert", self.conn.verify]
        auth = self.conn.session.headers.get("Authorization", "")
        if auth.startswith("Bearer "):
            env["COLORLAB_API_KEY"] = auth[len("Bearer "):]  # not on the command line, where ps would show it
        cmd += ["verify", os.fspath(path), "--against", *runs, "--json"]
        if scale is not None:
            cmd += ["--scale", repr(float(scale))]
        if lamp is not None or dimmer is not None:
            cmd += ["--lamp", str(lamp), "--dimmer", repr(float(dimmer))]
        if lens_calibration is not None:
            cmd += ["--lens-calibration", str(lens_calibration)]
        if not rendering_noise:
            cmd.append("--no-rendering-noise")
        if noise_neighbours is not None:
            cmd += ["--noise-neighbours", str(noise_neighbours)]
        if store:
            cmd.append("--store")
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S, env=env)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise VerifyFailed(1, f"{cmd[0]} could not be run: {e}") from e
        if p.returncode not in (EXIT_AGREES, EXIT_DIFFERS):
            raise VerifyFailed(p.returncode, p.stderr.strip().replace("colorlab: ", "", 1))
        result = json.loads(p.stdout)
        result["table"] = pd.DataFrame(result.get("comparisons", []))
        return result
