"""Flow curves as a family (``spherecontact.model.flow``): each law against its formula and a
finite difference, the registry round trip, a law registered in one file, the model with a Voce
curve against the campaign's table of it, Ludwik and tables bit for bit as before, and a tiny FE
run with a Swift curve against the same curve as a dense table."""

import math
import re
from dataclasses import dataclass

import numpy as np
import pytest

from spherecontact.campaign.design import VOCE_STRAINS, _body1
from spherecontact.cli import build_parser, join_negative_values, main
from spherecontact.fem import read_run
from spherecontact.fem.plasticity import solve_plastic_multiplier
from spherecontact.model import Material, Sphere, contact
from spherecontact.model.cli_args import material2_from_args, material_from_args
from spherecontact.model.flow import (
    REGISTRY,
    FlowCurve,
    Linear,
    Ludwik,
    Swift,
    Table,
    Voce,
    check_parameter,
    flow_from_description,
    flow_from_spec,
    register,
)

EPS = np.array([1e-4, 3e-3, 0.02, 0.1, 0.4, 1.5])

LAWS = [
    (Ludwik(2.0, K=3.0, n=0.4), lambda e: 2.0 + 3.0 * e**0.4, lambda e: 1.2 * e**-0.6),
    (Ludwik(2.0, K=3.0, n=1.0), lambda e: 2.0 + 3.0 * e, lambda e: 3.0 + 0 * e),
    (Swift(2.0, eps0=0.01, n=0.3), lambda e: 2.0 * (1 + e / 0.01) ** 0.3,
     lambda e: 2.0 * 30.0 * (1 + e / 0.01) ** -0.7),
    (Voce(2.0, Q=1.5, b=12.0), lambda e: 2.0 + 3.0 * (1 - np.exp(-12 * e)),
     lambda e: 36.0 * np.exp(-12 * e)),
    (Linear(2.0, H=5.0), lambda e: 2.0 + 5.0 * e, lambda e: 5.0 + 0 * e),
]


@pytest.mark.parametrize("law, stress, slope", LAWS, ids=lambda x: getattr(x, "name", ""))
def test_stress_and_slope_against_formula_and_finite_difference(law, stress, slope):
    assert law.sigma_y == 2.0 and float(law.stress(0.0)) == pytest.approx(2.0, rel=1e-15)
    np.testing.assert_allclose(law.stress(EPS), stress(EPS), rtol=1e-13)
    np.testing.assert_allclose(law.slope(EPS), slope(EPS), rtol=1e-12)
    d = 1e-6 * EPS
    fd = (law.stress(EPS + d) - law.stress(EPS - d)) / (2 * d)
    np.testing.assert_allclose(law.slope(EPS), fd, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(law.log_slope(EPS), EPS * slope(EPS) / stress(EPS), rtol=1e-12)
    assert np.all(law.stress(-1.0) == law.stress(0.0))  # negative strains read as 0
    # the strain-averaged stress is the average of the curve, whatever the law's own form
    W = 0.4
    sig, m = law.representative(EPS, W)
    nodes = [(1.0, 2 / 3), (math.exp(-W * math.sqrt(3)), 1 / 6), (math.exp(W * math.sqrt(3)), 1 / 6)]
    np.testing.assert_allclose(sig, sum(w * stress(f * EPS) for f, w in nodes), rtol=1e-12)
    assert np.all((m >= 0) & (m <= 1.0 + 1e-12))


def test_table_interpolates_and_continues_with_the_last_slope():
    t = Table([0.0, 0.1, 0.3], [1.0, 2.0, 2.5])
    np.testing.assert_allclose(t.stress([0.05, 0.2, 0.5]), [1.5, 2.25, 3.0])
    np.testing.assert_allclose(t.slope([0.0, 0.1, 0.5]), [10.0, 2.5, 2.5])  # right derivative
    assert t.sigma_y == 1.0 and t.segments == 2 and list(t.segment([0.05, 0.2, 9.0])) == [0, 1, 1]
    assert Table.of(Linear(1.0, H=2.0), [0.0, 1.0]) == Table([0.0, 1.0], [1.0, 3.0])


@pytest.mark.parametrize("make, message", [
    (lambda: Swift(1.0, eps0=0.0, n=0.2), "swift: eps0 = 0.0 is outside the allowed range (0, 5]"),
    (lambda: Swift(1.0, eps0=0.01, n=1.5), "swift: n = 1.5 is outside the allowed range [0, 1]"),
    (lambda: Voce(1.0, Q=-1.0, b=3.0), "voce: Q = -1.0 is outside the allowed range [0, 10000]"),
    (lambda: Voce(1.0, Q=1.0, b=math.nan), "voce: b = nan"),
    (lambda: Linear(0.0, H=1.0), "linear: sigma_y = 0.0 is outside the allowed range (0, inf)"),
    (lambda: Ludwik(1.0, K=2.0, n=0.0), "n = 0 with K = 2.0 > 0"),
    (lambda: Table([0.0, 20.0], [1.0, 2.0]), "plastic strains look like per cent"),
])
def test_parameters_are_checked_once_in_the_constructor(make, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        make()


@pytest.mark.parametrize("spec, law", [
    ("voce:Q=2,b=10", Voce(1.5, Q=2.0, b=10.0)),
    ("swift:eps0=0.02,n=0.25", Swift(1.5, eps0=0.02, n=0.25)),
    ("linear:H=3", Linear(1.5, H=3.0)),
    ("ludwik:K=2,n=0.3", Ludwik(1.5, K=2.0, n=0.3)),
    ("LUDWIK", Ludwik(1.5)),
])
def test_registry_round_trip_spec_object_description_object(spec, law):
    made = flow_from_spec(spec, sigma_y=1.5)
    assert made == law
    d = made.describe()
    assert d["flow"] == made.name and d["sigma_y"] == 1.5
    assert flow_from_description(d) == made
    assert flow_from_spec(made.spec(), sigma_y=1.5) == made
    assert flow_from_spec(spec + ("," if ":" in spec else ":") + "sigma_y=1.5") == made  # σ_Y inside
    m = Material.with_flow(300.0, 0.3, made)
    assert Material.from_description(m.describe()) == m
    t = Table([0.0, 0.5], [1.0, 1.2])
    assert flow_from_description(t.describe()) == t


@pytest.mark.parametrize("spec, sigma_y, message", [
    ("hollomon:K=2", 1.0, "unknown flow curve 'hollomon'; known: linear, ludwik, swift, table, voce"),
    ("voce:Q=2,c=3", 1.0, "unknown parameter 'c' of voce; allowed: sigma_y, Q, b"),
    ("voce:Q=2", 1.0, "voce needs b"),
    ("voce:Q=two,b=1", 1.0, "Q = 'two' is not a number"),
    ("voce:Q=2,b=1", None, "needs the initial yield stress sigma_y"),
    ("table", 1.0, "give it as a CSV file"),
])
def test_registry_errors_name_the_spec_and_the_allowed_values(spec, sigma_y, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        flow_from_spec(spec, sigma_y=sigma_y)


def test_a_new_law_is_one_class_and_one_register_line():
    @dataclass(frozen=True)
    class Hockett(FlowCurve):  # σ_f = σ_Y + Q σ_Y (1 − exp(−(ε/ε_c)^p)), Hockett–Sherby
        name = "hockett"
        kind = "Hockett–Sherby curve"
        sigma_y: float
        Q: float
        eps_c: float
        p: float = 0.8

        def __post_init__(self):
            check_parameter(self.name, "Q", self.Q, 0.0)
            check_parameter(self.name, "eps_c", self.eps_c, 0.0, lo_open=True)

        def _stress(self, e):
            return self.sigma_y * (1.0 + self.Q * -np.expm1(-(e / self.eps_c) ** self.p))

        def _slope(self, e):
            x = np.maximum(e, 1e-12) / self.eps_c
            return self.sigma_y * self.Q * self.p / self.eps_c * x ** (self.p - 1) * np.exp(-x**self.p)

    try:
        register(Hockett)
        law = flow_from_spec("hockett:Q=1,eps_c=0.05", sigma_y=1.0)
        assert law == Hockett(1.0, 1.0, 0.05) and flow_from_description(law.describe()) == law
        m = Material.with_flow(500.0, 0.3, law)
        st = contact(Sphere(1.0, m), Sphere(math.inf, Material.rigid()), np.geomspace(1e-4, 0.1, 5))
        assert np.all(np.diff(st.F) > 0) and np.all(np.isfinite(st.F))
        # the FE's return mapping reads the same curve
        dg = solve_plastic_multiplier(np.array([3.0]), np.array([0.0]), m, 100.0)
        assert 3.0 - 300.0 * dg[0] == pytest.approx(float(law.stress(dg[0])), rel=1e-10)
        with pytest.raises(ValueError, match="hockett: eps_c = 0"):
            flow_from_spec("hockett:Q=1,eps_c=0", sigma_y=1.0)
    finally:
        REGISTRY.pop("hockett", None)


def test_voce_in_the_model_equals_the_campaigns_table_of_it():
    p = {"sigma_y": 1.0, "E_over_sigma_y": 300.0, "nu": 0.3, "K_over_sigma_y": 0.0, "n": 1.0,
         "Q_over_sigma_y": 2.0, "b": 10.0}
    tab = _body1(p, {})
    assert tab.is_tabulated and tab.eps_table == VOCE_STRAINS
    voce = Material.with_flow(300.0, 0.3, flow_from_spec("voce:Q=2,b=10", sigma_y=1.0))
    # the table is the curve at its nodes (to its rounding)
    np.testing.assert_allclose(tab.sigma_table, voce.flow_stress(VOCE_STRAINS), rtol=1e-9)
    h = np.geomspace(1e-4, 0.2, 25)
    flat = Sphere(math.inf, Material.rigid())
    for partner in (flat, None):
        a = contact(Sphere(1.0, voce), partner or Sphere(1.0, voce), h)
        b = contact(Sphere(1.0, tab), partner or Sphere(1.0, tab), h)
        np.testing.assert_allclose(a.F, b.F, rtol=3e-3)  # the table's interpolation error
        np.testing.assert_allclose(a.a, b.a, rtol=1e-3)


#: the model's F (and a) and the FE multiplier of Ludwik and table materials as computed before the
#: flow curves became a family (float.hex)
REFERENCE_LUDWIK = [
    "0x1.d322bbb456051p-17", "0x1.5be7083a04764p-13", "0x1.ea52510f8fb68p-10",
    "0x1.2837837d84ca9p-6", "0x1.33fd28b23950bp-3", "0x1.0354d8e1d39b3p+0", "0x1.ee9572b2d52dbp+1",
    "0x1.9e9270c7998abp-9", "0x1.d946b9c22e9c2p-8", "0x1.163e774a3e26ep-6", "0x1.611177b1e3b4ap-5",
    "0x1.bfd5b6857db34p-4", "0x1.108dacc490d99p-2", "0x1.216e3c1498a9ap-1",
    "0x1.7d2f384e43477p-18", "0x1.1baa4f1246f34p-14", "0x1.a66c5977631adp-11",
    "0x1.163b98c6d8af2p-7", "0x1.3cd6e460363c1p-4", "0x1.31d6d612dde90p-1", "0x1.845f9be99f5afp+1",
]
REFERENCE_TABLE = [
    "0x1.376c769304b44p-17", "0x1.cfde73a0c4a55p-14", "0x1.517c97d7455dap-10",
    "0x1.a28d53416c28ap-7", "0x1.bf82cf5e1b28ep-4", "0x1.8d671187991dep-1", "0x1.7a45d19722f19p+1",
    "0x1.9e9256642e044p-9", "0x1.d945ad12e7057p-8", "0x1.11805b8a7ec2cp-6", "0x1.595b162312e2dp-5",
    "0x1.b78aa73bb3a23p-4", "0x1.0d0a0685d3193p-2", "0x1.2102642862d45p-1",
    "0x1.fc3ef1ca75003p-19", "0x1.7a3852e47490ap-15", "0x1.19ea818b6c793p-11",
    "0x1.831f4387f9dbbp-8", "0x1.c5a70382edcb7p-5", "0x1.c22357c3cb8aap-2", "0x1.27b12ea43452cp+1",
]
REFERENCE_MULTIPLIER = [
    "0x0.0p+0", "0x1.b6492afcecc54p-9", "0x1.b93151e09aabep-8", "0x1.4c634cd24ea8bp-7",
    "0x1.bcbf0847e441bp-7",
]


def test_ludwik_and_tables_give_the_numbers_they_gave_before_bit_for_bit():
    h = np.geomspace(1e-5, 0.2, 7)
    flat = Sphere(math.inf, Material.rigid())
    lud = Material(E=300.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3)
    table = Material.from_table(200.0, 0.3, [0.0, 0.02, 0.1, 0.5], [1.0, 1.3, 1.6, 2.0])
    for m, ref in ((lud, REFERENCE_LUDWIK), (table, REFERENCE_TABLE)):
        st, st2 = contact(Sphere(1.0, m), flat, h), contact(Sphere(1.0, m), Sphere(2.0, m), h)
        got = np.concatenate([st.F, st.a, st2.F])
        assert [x.hex() for x in got] == ref
    q = np.linspace(1.0, 3.0, 5) * 1.5
    dg = solve_plastic_multiplier(q, np.full(5, 0.01), lud, 70.0)
    assert [x.hex() for x in dg] == REFERENCE_MULTIPLIER
    # the same Ludwik curve through every entrance is the same material
    same = [Material.with_flow(300.0, 0.3, Ludwik(1.0, 2.0, 0.3)),
            Material.with_flow(300.0, 0.3, flow_from_spec("ludwik:K=2,n=0.3", sigma_y=1.0)),
            Material.from_description(lud.describe())]
    assert all(s == lud and hash(s) == hash(lud) for s in same)
    # descriptions of the stored runs keep their keys
    assert lud.describe() == {"E": 300.0, "nu": 0.3, "sigma_y": 1.0, "K": 2.0, "n": 0.3}
    assert list(table.describe()) == ["E", "nu", "eps_table", "sigma_table"]
    assert Material.with_flow(300.0, 0.3, Voce(1.0, 2.0, 10.0)).describe() == {
        "E": 300.0, "nu": 0.3, "flow": "voce", "sigma_y": 1.0, "Q": 2.0, "b": 10.0}
    assert lud != Material.with_flow(300.0, 0.3, Swift(1.0, 0.01, 0.3))


def _args(*argv):
    return build_parser().parse_args(join_negative_values(
        ["fem", "run", "--E", "200", "--nu", "0.3", *argv, "--h-max", "0.01", "--out", "x.h5"]))


def test_cli_flow_and_flow2():
    args = _args("--sigma-y", "1.5", "--flow", "voce:Q=2,b=10", "--flow2", "swift:eps0=0.01,n=0.2",
                 "--E2", "100")
    m1 = material_from_args(args)
    assert m1 == Material.with_flow(200.0, 0.3, Voce(1.5, 2.0, 10.0))
    assert material2_from_args(args, m1) == Material.with_flow(100.0, 0.3, Swift(1.5, 0.01, 0.2))
    # body 2 takes body 1's curve, or its law with the parameters given for body 2
    args = _args("--sigma-y", "1.5", "--flow", "swift:eps0=0.01,n=0.2", "--E2", "100", "--n2", "0.4")
    assert material2_from_args(args, material_from_args(args)) == Material.with_flow(
        100.0, 0.3, Swift(1.5, 0.01, 0.4))
    args = _args("--sigma-y", "1.5", "--flow", "voce:Q=2,b=10", "--E2", "100")
    assert material2_from_args(args, material_from_args(args)).flow == Voce(1.5, 2.0, 10.0)


@pytest.mark.parametrize("argv, message", [
    (["--sigma-y", "1", "--flow", "voce:Q=2"], "--flow voce:Q=2: 'voce:Q=2': voce needs b"),
    (["--sigma-y", "1", "--flow", "power:n=2"], "--flow power:n=2: 'power:n=2': unknown flow curve"),
    (["--sigma-y", "1", "--flow", "voce:Q=2,b=10", "--K", "2"], "--flow gives the hardening; drop --K"),
    (["--flow", "voce:Q=2,b=10"], "needs the initial yield stress sigma_y"),
    (["--sigma-y", "1", "--flow", "voce:Q=2,b=10", "--E2", "100", "--K2", "2"],
     "--K2 is not a parameter of body 1's flow curve voce"),
])
def test_cli_flow_errors_name_the_flag_the_value_and_the_allowed_names(argv, message, tmp_path, capsys):
    code = main(["fem", "run", "--E", "200", *argv, "--h-max", "0.01", "--out", str(tmp_path / "r.h5")])
    assert code == 2
    assert message in capsys.readouterr().err


def test_fem_run_with_a_swift_curve_matches_the_same_curve_as_a_dense_table(tmp_path):
    swift = Swift(1.0, eps0=0.01, n=0.3)
    eps = np.concatenate([[0.0], np.geomspace(1e-6, 4.0, 400)])
    table = tmp_path / "swift.csv"
    rows = zip(eps, swift.stress(eps), strict=True)
    table.write_text("eps_p,sigma\n" + "".join(f"{e:.17g},{s:.17g}\n" for e, s in rows))
    common = ["--E", "200", "--nu", "0.3", "--radius", "1", "--h-max", "0.01", "--mesh-density", "0.25",
              "--quiet"]
    runs = {}
    for name, flow in (("swift", ["--sigma-y", "1", "--flow", "swift:eps0=0.01,n=0.3"]),
                       ("table", ["--flow-table", str(table)])):
        out = tmp_path / f"{name}.h5"
        assert main(["fem", "run", *common, *flow, "--out", str(out)]) == 0
        runs[name] = read_run(out)
    assert runs["swift"].status == "converged"
    assert runs["swift"].material().flow == swift
    assert runs["swift"].inputs["material"]["flow"] == "swift"
    assert runs["swift"].F[-1] == pytest.approx(runs["table"].F[-1], rel=5e-3)
