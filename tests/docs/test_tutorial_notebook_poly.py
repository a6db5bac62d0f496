"""The notebook tutorial (``docs/tutorials/notebook-poly.md``) runs as written: its
``python`` blocks are executed in order in one namespace (the cells of a notebook) in an
empty folder, each block's printed numbers equal the ``text`` block the page shows after it,
and the results are the truth the page draws its arrays from: the coefficients of
0.3 + 0.025 T − 2·10⁻⁴ T² within 3 standard errors, the residual and the compensated output
at the white noise σ = 0.05 °/h (and σ/√100 over 100 s averages), the model's value within
a few 1e-4 °/h of the true bias, and the C module, compiled, giving the corrected output
the library gives."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tutorial_pages import BLOCK, TUTORIALS, _numbers

PAGE = TUTORIALS / "notebook-poly.md"
SIGMA = 0.05  # [°/h] the page's white noise
TRUTH = {"const": 0.3, "T1": 0.025, "T1^2": -2.0e-4}  # the page's true_bias [°/h, /°C, /°C²]


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[tuple[str, str]], dict[str, Any]]:
    """(printed, shown) per python block, and the namespace the blocks ran in."""
    here = tmp_path_factory.mktemp("notebook")
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(PAGE.read_text(encoding="utf-8"))]
    ns: dict[str, Any] = {}
    pairs = []
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(here)
        for i, (lang, body) in enumerate(blocks):
            if lang != "python":
                continue
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(compile(body, f"notebook-poly block {i}", "exec"), ns)
            shown = next(b for la, b in blocks[i + 1 :] if la == "text")
            pairs.append((out.getvalue(), shown))
    ns["__folder__"] = here
    return pairs, ns


def test_the_page_prints_what_it_shows(page: tuple[list[tuple[str, str]], dict[str, Any]]) -> None:
    pairs, _ = page
    assert len(pairs) == 5
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)
        assert printed.strip().splitlines() == shown.strip().splitlines()


def test_the_fit_is_the_truth(page: tuple[list[tuple[str, str]], dict[str, Any]]) -> None:
    _, ns = page
    coefs = {c.name: c for c in ns["model"].coefficients()}
    assert set(coefs) == set(TRUTH)
    for name, value in TRUTH.items():
        assert abs(coefs[name].value - value) < 3 * coefs[name].stderr, name
    # the residual is the white noise: σ within its sampling error (√(2/n) relative)
    n = ns["runs"]["modelling"].n_samples
    assert ns["model"].stats_.rms_residual == pytest.approx(SIGMA, rel=3 * np.sqrt(2 / n))


def test_validation_and_compensation_leave_the_noise(
    page: tuple[list[tuple[str, str]], dict[str, Any]],
) -> None:
    _, ns = page
    val = ns["runs"]["validation"]
    temp = val.temps_c[:, 0]
    bias = TRUTH["const"] + TRUTH["T1"] * temp + TRUTH["T1^2"] * temp**2
    out = ns["out"]
    assert np.max(np.abs(out.model_value - bias)) < 2e-3
    np.testing.assert_allclose(out.corrected, val.signal - out.model_value, rtol=0, atol=1e-12)
    assert out.corrected.std() == pytest.approx(SIGMA, rel=0.05)
    res = ns["result"]
    assert abs(res.r) < 0.4 and res.weakly_correlated
    # 100 s averages of white noise: σ/√100, computed here on the corrected output
    k = val.n_samples // 100
    blocks = out.corrected[: k * 100].reshape(k, 100).mean(axis=1)
    assert res.rms_after == pytest.approx(blocks.std(), rel=0.1)
    assert res.rms_after == pytest.approx(SIGMA / 10, rel=0.1)


def test_the_c_module_corrects_as_the_library_does(
    page: tuple[list[tuple[str, str]], dict[str, Any]],
) -> None:
    """The exported C, compiled with a small main of this test, gives the corrected output
    of ``compensate_run`` on the validation run's first samples."""
    from thermocal.export.c import find_compiler

    cc = find_compiler()
    if cc is None:
        pytest.skip("no C compiler")
    _, ns = page
    here: Path = ns["__folder__"]
    val = ns["runs"]["validation"]
    idx = np.arange(0, val.n_samples, 997)
    rows = "\n".join(
        f"{{{float(val.time_s[i])!r}, {float(val.temps_c[i, 0])!r}, {float(val.signal[i])!r}}},"
        for i in idx
    )
    (here / "main.c").write_text(
        '#include <stdio.h>\n#include "gyro_x.h"\n'
        f"static const double rows[][3] = {{\n{rows}\n}};\n"
        "int main(void) {\n  gyro_x_state s;\n  gyro_x_init(&s, 1.0);\n"
        "  for (unsigned i = 0; i < sizeof rows / sizeof rows[0]; ++i) {\n"
        "    gyro_x_real t[1] = {rows[i][1]};\n"
        '    printf("%.17g\\n", gyro_x_compensate(&s, rows[i][0], t, rows[i][2]));\n  }\n'
        "  return 0;\n}\n",
        encoding="utf-8",
    )
    import subprocess

    exe = here / "main"
    subprocess.run(
        [cc, "-std=c99", "-O2", "-o", str(exe), "main.c", "gyro_x.c", "-lm"],
        cwd=here,
        check=True,
        capture_output=True,
    )
    got = np.array([float(v) for v in subprocess.run(
        [str(exe)], check=True, capture_output=True, text=True
    ).stdout.split()])  # fmt: skip
    np.testing.assert_allclose(got, ns["out"].corrected[idx], rtol=0, atol=1e-9)
