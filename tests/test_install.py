"""An ordinary install gives the repository's answers.

The sdist is built, the wheel is built from it (``python -m build``), and the wheel is
installed with pip into a fresh virtual environment outside the repository; a script run
there from another directory evaluates F, a and the unloading branch of three pairs, which
must equal this checkout's values to 1e-12. The fresh environment takes its dependencies
(numpy, scipy, …) from this one through a ``.pth`` line, which adds the directory but not its
editable-install hooks, so ``spherecontact`` can only come from the wheel.
"""

from __future__ import annotations

import json
import subprocess
import sys
import sysconfig
import tarfile
import zipfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGED = "spherecontact/model/coefficients.json"

#: evaluated in this process and in the fresh environment; prints JSON
SCRIPT = r'''
import json, math, sys
import numpy as np
import spherecontact
from spherecontact.model import ContactLaw, Material, Sphere, contact, default_coefficients

steel = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
alu = Material.from_table(E=70e9, nu=0.33, eps_p=[0.0, 0.02, 0.1, 0.4],
                          sigma=[120e6, 160e6, 200e6, 230e6])
pairs = {
    "equal": (Sphere(1e-3, steel), Sphere(1e-3, steel)),
    "steel_aluminium_table": (Sphere(1e-3, steel), Sphere(2e-3, alu)),
    "rigid_flat": (Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0)),
                   Sphere(math.inf, Material.rigid())),
}
out = {"file": spherecontact.__file__, "source": default_coefficients().source}
for name, (s1, s2) in pairs.items():
    R = min(s1.radius, s2.radius)
    h = R * np.geomspace(1e-4, 0.1, 12)
    hm = 0.1 * R
    load = contact(s1, s2, h)
    unload = contact(s1, s2, np.linspace(0.99, 0.90, 6) * hm, h_max=hm)
    law = ContactLaw(s1, s2)
    F_law, k_law = law.force(np.linspace(0.99, 0.5, 6) * hm, hm)
    out[name] = {"F": load.F.tolist(), "a": load.a.tolist(), "F_unload": unload.F.tolist(),
                 "a_unload": unload.a.tolist(), "F_law": F_law.tolist(), "k_law": k_law.tolist()}
json.dump(out, sys.stdout)
'''


def _run(python: str, cwd: Path, env: dict | None = None) -> dict:
    res = subprocess.run([python, "-c", SCRIPT], cwd=cwd, capture_output=True, text=True, env=env,
                         check=False)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout)


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, Path]:
    """(python of a fresh venv with the wheel installed, the built sdist)."""
    tmp = tmp_path_factory.mktemp("install")
    dist = tmp / "dist"
    build = subprocess.run([sys.executable, "-m", "build", "--outdir", str(dist), str(ROOT)],
                           capture_output=True, text=True, check=False)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    wheel = next(dist.glob("*.whl"))
    sdist = next(dist.glob("*.tar.gz"))
    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    (Path(site) / "dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    pip = subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-deps", "--no-index", str(wheel)],
                         capture_output=True, text=True, check=False)
    assert pip.returncode == 0, pip.stderr[-3000:]
    return python, sdist


def test_sdist_and_wheel_carry_the_calibrated_coefficients(installed):
    python, sdist = installed
    wheel = next(sdist.parent.glob("*.whl"))
    with zipfile.ZipFile(wheel) as zf:
        shipped = zf.read(PACKAGED)
    with tarfile.open(sdist) as tf:
        in_sdist = [n for n in tf.getnames() if n.endswith("model/coefficients.json")]
    assert in_sdist, "the sdist lacks model/coefficients.json"
    assert shipped == (ROOT / "model" / "coefficients.json").read_bytes()


def test_installed_wheel_gives_the_repository_values(installed, tmp_path):
    python, _ = installed
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    got = _run(str(python), elsewhere)
    want = _run(sys.executable, ROOT)
    assert Path(got["file"]).resolve().is_relative_to(python.parent.parent.resolve()), got["file"]
    assert not Path(got["file"]).resolve().is_relative_to(ROOT)
    assert got["source"] == want["source"] == "calibration"
    for pair in ("equal", "steel_aluminium_table", "rigid_flat"):
        for key, ref in want[pair].items():
            ref = np.asarray(ref)
            assert np.any(ref > 0.0), (pair, key)
            np.testing.assert_allclose(got[pair][key], ref, rtol=1e-12, atol=0.0, err_msg=f"{pair} {key}")


def test_missing_packaged_file_is_an_error_that_says_how_to_restore_it(installed, tmp_path):
    """Delete the installed JSON: the default set is refused, never replaced by the literature set."""
    python, _ = installed
    site = Path(subprocess.run([str(python), "-c", "import spherecontact.model as m, os; "
                                "print(os.path.dirname(m.__file__))"],
                               capture_output=True, text=True, check=True, cwd=tmp_path).stdout.strip())
    packaged = site / "coefficients.json"
    saved = packaged.read_bytes()
    packaged.unlink()
    try:
        res = subprocess.run([str(python), "-c", "from spherecontact.model import load_coefficients as l; "
                              "print(l('literature').source); l()"],
                             capture_output=True, text=True, cwd=tmp_path, check=False)
    finally:
        packaged.write_bytes(saved)
    assert res.returncode != 0 and res.stdout.strip() == "literature"
    assert "coefficients.json" in res.stderr and "Reinstall" in res.stderr
