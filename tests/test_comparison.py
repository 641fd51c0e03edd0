"""Comparisons: the file format, the mission shared by every method, the same draws, the report."""
import dataclasses as dc
import json

import numpy as np
import pytest
from pydrake.common.yaml import yaml_dump_typed
from scipy import stats

from drake_entry.comparison.report import clopper_pearson, dispersion_check, method_summary
from drake_entry.comparison.spec import (
    PACKAGED_COMPARISONS,
    ComparedMethod,
    Comparison,
    load_comparison,
    method_scenario,
    needs_derivation,
)
from drake_entry.errors import ScenarioError
from drake_entry.guidance import REGISTRY
from drake_entry.guidance.bank_profile.spec import BankProfile
from drake_entry.scenario import load_scenario


@pytest.mark.parametrize("name", PACKAGED_COMPARISONS)
def test_a_packaged_comparison_accounts_for_every_registered_method(name):
    """Each listed method says how the mission maps to it or why it is not flown; a registered
    method the file does not list is a not-flown entry 'not configured' (no hand-written line)."""
    comp = load_comparison(name)
    for m in comp.methods:
        assert m.mapping or m.not_flown, f"{m.label}: say how the mission maps to it, or why it is not flown"
    unlisted = comp.not_configured()
    assert {m.method for m in comp.methods + unlisted} == {spec.__name__ for spec in REGISTRY}
    assert all(m.not_flown.startswith("not configured") for m in unlisted)


def test_a_method_the_comparison_does_not_list_is_reported_not_configured():
    comp = Comparison(name="one", mission="horus2b", methods=[
        ComparedMethod(label="bank_profile", method="BankProfile", mapping="m")]).validate()
    unlisted = {m.method: m for m in comp.not_configured()}
    assert set(unlisted) == {spec.__name__ for spec in REGISTRY} - {"BankProfile"}
    assert unlisted["DragEnergy"].label == "drag_energy" and not unlisted["DragEnergy"].guidance
    assert "not configured: this comparison does not list !DragEnergy (list it without a guidance block to derive" in unlisted["DragEnergy"].not_flown


@pytest.mark.parametrize("name", PACKAGED_COMPARISONS)
def test_every_flown_method_shares_the_mission_and_flies_its_own_method(name):
    """Each flown entry's scenario (written settings, the mission's own, or those derived from the
    mission: the derivation's first candidates here) is the mission but for the method's settings."""
    from drake_entry.comparison.derive import apply_derivation
    from drake_entry.comparison.spec import needs_derivation
    from drake_entry.guidance.derivation import derivation_for

    comp = load_comparison(name)
    mission = load_scenario(comp.mission)
    specs = {spec.__name__: spec for spec in REGISTRY}
    for m in comp.flown():
        derived = (apply_derivation(mission, derivation_for(mission, specs[m.method]))
                   if needs_derivation(comp, m, mission) else None)
        s = method_scenario(comp, m, derived)
        assert type(s.guidance).__name__ == m.method
        assert s.name == f"{mission.name}-{m.label}"
        # everything but the method's own settings (guidance, alpha) is the mission, to the byte
        s.name, s.guidance, s.alpha = mission.name, mission.guidance, mission.alpha
        assert yaml_dump_typed(s) == yaml_dump_typed(mission), m.label


def _comparison(**entry) -> Comparison:
    return Comparison(name="t", mission="horus2b", methods=[ComparedMethod(**{"label": "a", "method": "DragEnergy",
                                                                              "mapping": "x", **entry})])


@pytest.mark.parametrize("entry, words", [
    ({"overrides": {"entry.altitude_km": "121"}}, "entry.altitude_km: only the method's settings"),
    ({"overrides": {"dispersions.density_scale": "!Uniform {min: 0.9, max: 1.1}"}}, "dispersions.density_scale"),
    ({"method": "Foo"}, "method = 'Foo'; allowed: DragEnergy"),
    ({"label": "a b"}, "label = 'a b'"),
    ({"not_flown": "why", "overrides": {"guidance.period_s": "2"}}, "not_flown and settings"),
    ({"guidance": BankProfile()}, "guidance is !BankProfile but method is DragEnergy"),
])
def test_a_bad_entry_is_one_line_naming_it(entry, words):
    with pytest.raises(ScenarioError, match=None) as e:
        _comparison(**entry).validate()
    assert words in str(e.value) and "\n" not in str(e.value)


def test_a_label_given_twice_and_an_entry_whose_settings_do_not_fit_are_refused():
    comp = _comparison()
    comp.methods.append(dc.replace(comp.methods[0]))
    with pytest.raises(ScenarioError, match="label = 'a' is given twice"):
        comp.validate()
    bad = _comparison(overrides={"guidance.terminal_mach": "99"}).validate()
    with pytest.raises(ScenarioError, match=r"comparison t, method a: .*guidance.terminal_mach = 99"):
        method_scenario(bad, bad.methods[0])
    derived = _comparison(method="Fnpeg").validate()  # the mission flies !DragEnergy: settings derived
    assert needs_derivation(derived, derived.methods[0]) and not needs_derivation(comp, comp.methods[0])
    with pytest.raises(ScenarioError, match="gives no guidance: !Fnpeg block: its settings are derived from the mission"):
        method_scenario(derived, derived.methods[0])


def test_a_comparison_file_is_read_and_checked_like_a_scenario(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("name: c\nmission: horus2b\nmethods:\n  - {label: de, method: DragEnergy, mapping: own}\n"
                    "  - label: bp\n    method: BankProfile\n    guidance: !BankProfile {bank_start_deg: 66.0}\n"
                    "    mapping: fixed\n  - {label: s, method: Scvx, not_flown: 'no DRS box'}\n")
    comp = load_comparison(str(path))
    assert [m.label for m in comp.flown()] == ["de", "bp"]
    assert method_scenario(comp, comp.methods[1]).guidance.bank_start_deg == 66.0
    path.write_text("name: c\nmission: horus2b\nmethods:\n  - {label: de, method: DragEnergy, mapingg: own}\n")
    with pytest.raises(ScenarioError, match="mapingg: unknown field; did you mean mapping"):
        load_comparison(str(path))
    with pytest.raises(ScenarioError, match="neither a packaged comparison"):
        load_comparison(str(tmp_path / "nope.yaml"))


@pytest.mark.parametrize("k, n", [(0, 10), (10, 10), (5, 10), (17, 20), (1, 1)])
def test_the_success_interval_is_the_exact_clopper_pearson_interval(k, n):
    lo, hi = clopper_pearson(k, n, 0.9)
    # the beta-quantile form of the exact interval (alpha/2 in each tail)
    want_lo = 0.0 if k == 0 else stats.beta.ppf(0.05, k, n - k + 1)
    want_hi = 1.0 if k == n else stats.beta.ppf(0.95, k + 1, n - k)
    assert lo == pytest.approx(want_lo, abs=1e-9) and hi == pytest.approx(want_hi, abs=1e-9)
    if 0 < k < n:
        assert lo < k / n < hi


def _rows(n, **cols):
    base = {"index": list(range(n)), "success": [True] * n, "reached_terminal": [True] * n,
            "err_distance_m": [100.0 * (i + 1) for i in range(n)], "disp_dh_m": [float(i) for i in range(n)]}
    return {**base, **cols}


def test_the_dispersion_check_finds_a_different_draw():
    a, b = _rows(3), _rows(3)
    assert dispersion_check({"a": a, "b": b}) == (True, 3, 0.0)
    b["disp_dh_m"] = [0.0, 1.0, 2.5]
    same, compared, worst = dispersion_check({"a": a, "b": b})
    assert not same and compared == 3 and worst == pytest.approx(0.5)


def test_the_method_summary_counts_and_measures_the_rows():
    rows = _rows(4, success=[True, False, True, True], inside_box=[True, False, True, True],
                 within_limits=[True, True, True, True], message=["ok", "outside the acceptance box: distance", "ok",
                                                                 "ok"],
                 err_range_m=[1000.0, -3000.0, 500.0, 0.0], margin_heat_flux=[0.1, 0.05, -0.01, 0.2],
                 bank_reversals=[2, 3, 4, 5], wall_time_s=[1.0, 2.0, 3.0, 4.0])
    s = method_summary(rows)
    assert (s["samples"], s["successful"], s["inside_box"]) == (4, 3, 3)
    assert s["successful_interval"] == pytest.approx(clopper_pearson(3, 4))
    assert s["miss_km"]["median"] == pytest.approx(0.25) and s["miss_km"]["max"] == pytest.approx(0.4)
    assert s["err_range_m"]["mean"] == pytest.approx(-375.0)
    assert s["err_range_m"]["std"] == pytest.approx(np.std([1000.0, -3000.0, 500.0, 0.0], ddof=1))
    assert s["margins"]["margin_heat_flux"] == {"worst": -0.01, "breached": 1}
    assert s["bank_reversals"] == {"mean": 3.5, "max": 5.0}


@pytest.mark.slow  # a campaign: out of the default run, in CI's -m "slow and not long" set
def test_two_methods_fly_the_same_draws_and_one_report_compares_them(tmp_path, monkeypatch, capsys):
    from drake_entry.comparison.runner import run_comparison
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup

    built = []  # pre-flight plans made in this process (workers=1 runs the samples here too)
    from_scenario = ClosedLoopSetup.from_scenario
    monkeypatch.setattr(ClosedLoopSetup, "from_scenario",
                        classmethod(lambda cls, *a, **k: built.append(a[0].name) or from_scenario(*a, **k)))

    comp = Comparison(name="tiny", description="drag-energy and a fixed bank profile", mission="horus2b", methods=[
        ComparedMethod(label="drag_energy", method="DragEnergy", mapping="the mission's own settings"),
        ComparedMethod(label="bank_profile", method="BankProfile", mapping="66 to 50 deg",
                       guidance=BankProfile(terminal_altitude_km=26.5, bank_start_deg=66.0, bank_end_deg=50.0)),
        ComparedMethod(label="ampi", method="Ampi", not_flown="no database of this vehicle")])
    path = run_comparison(comp, runs=2, out_dir=str(tmp_path / "cmp"), seed=7, workers=1, progress=False)
    text = open(path).read()
    summary = json.loads((tmp_path / "cmp" / "comparison_summary.json").read_text())
    assert summary["same_dispersions"] and summary["samples_compared"] == 2
    de, bp = summary["methods"]["drag_energy"], summary["methods"]["bank_profile"]
    assert de["successful"] == 2 and bp["successful"] == 0  # the fixed profile misses the 2-km box
    assert bp["miss_km"]["median"] > 2.0 > de["miss_km"]["max"]
    assert summary["not_flown"]["ampi"] == "no database of this vehicle"
    unlisted = {spec.__name__ for spec in REGISTRY} - {"DragEnergy", "BankProfile", "Ampi"}
    assert {k for k, v in summary["not_flown"].items() if v.startswith("not configured")} == {
        m.label for m in comp.not_configured()} and {m.method for m in comp.not_configured()} == unlisted
    assert "| ampi (!Ampi) | — | not flown |" in text and "| fnpeg (!Fnpeg) | — | not flown |" in text and "Same dispersions: sample i drew the same" in text
    assert "| [drag_energy](drag_energy/report.md) (!DragEnergy) | 2 | 2 [" in text
    for fig in ("comparison_footprints.png", "comparison_success.png", "comparison_miss.png"):
        assert (tmp_path / "cmp" / fig).stat().st_size > 10_000 and fig in text
    assert (tmp_path / "cmp" / "drag_energy" / "report.md").exists()
    # two plans per flown method: the timed one, which the nominal flight then flies, and the
    # worker's (one process here); the nominal flight used to plan a third time
    assert sorted(built) == ["horus2b-bank_profile"] * 2 + ["horus2b-drag_energy"] * 2 and all((tmp_path / "cmp" / m / "nominal.json").exists() for m in ("drag_energy", "bank_profile"))
    assert "guidance: !BankProfile" in (tmp_path / "cmp" / "scenarios" / "bank_profile.yaml").read_text()
    # `drake-entry report` on a comparison directory rewrites the comparison's report (it advised `campaign`)
    from drake_entry.cli import main

    (tmp_path / "cmp" / "report.md").unlink()
    capsys.readouterr()
    assert main(["report", str(tmp_path / "cmp")]) == 0 and (tmp_path / "cmp" / "report.md").read_text() == text
    assert "drag_energy: 2 of 2 successful" in capsys.readouterr().out
    # a second call with another seed into the same directory is refused, not mixed
    with pytest.raises(ScenarioError, match="holds comparison 'tiny' with seed 7"):
        run_comparison(comp, runs=2, out_dir=str(tmp_path / "cmp"), seed=8, workers=1, progress=False)


@pytest.mark.slow  # a 1-sample campaign and its report: about 10 s
def test_a_method_left_out_by_only_never_keeps_a_reason_that_no_longer_holds(tmp_path):
    """A derived method not flown in a run with --only keeps no earlier 'not flown' reason: its
    settings derive from the mission now (the LGL terminal guidance's 'it solves a problem file'
    stayed in the matrix after it learnt to pose a mission's problem)."""
    from drake_entry.comparison.runner import run_comparison

    comp = Comparison(name="tiny", mission="horus2b", methods=[
        ComparedMethod(label="bank_profile", method="BankProfile",
                       guidance=BankProfile(terminal_altitude_km=26.5, bank_start_deg=66.0, bank_end_deg=50.0)),
        ComparedMethod(label="fnpeg", method="Fnpeg")])
    out = tmp_path / "cmp"
    run_comparison(comp, runs=1, out_dir=str(out), seed=7, workers=1, only=["bank_profile"], progress=False)
    manifest = json.loads((out / "comparison.json").read_text())
    manifest["methods"]["fnpeg"]["reason"] = "an old reason"
    (out / "comparison.json").write_text(json.dumps(manifest))
    run_comparison(comp, runs=1, out_dir=str(out), seed=7, workers=1, only=["bank_profile"], progress=False)
    fnpeg = json.loads((out / "comparison.json").read_text())["methods"]["fnpeg"]
    assert not fnpeg["flown"] and fnpeg["reason"].startswith("yet to fly in this directory: its settings derive")


@pytest.mark.slow  # two 1-sample campaigns and a report: about 15 s
def test_an_interrupted_comparison_resumes_with_the_same_command_keeping_its_samples(tmp_path, monkeypatch):
    """A run stopped inside a method's campaign leaves a comparison.json naming that method as
    unfinished; the same command then resumes it, the finished sample kept as it was (a 100-run
    campaign stopped at 87 samples could not be resumed: the manifest was written only after it)."""
    import drake_entry.comparison.runner as runner

    comp = Comparison(name="tiny", mission="horus2b", methods=[
        ComparedMethod(label="bank_profile", method="BankProfile",
                       guidance=BankProfile(terminal_altitude_km=26.5, bank_start_deg=66.0, bank_end_deg=50.0))])
    out = tmp_path / "cmp"
    real = runner.run_campaign

    def stopped(path, *, runs, **kw):  # one sample flown, then Ctrl-C
        real(path, runs=1, **kw)
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "run_campaign", stopped)
    with pytest.raises(KeyboardInterrupt):
        runner.run_comparison(comp, runs=2, out_dir=str(out), seed=7, workers=1, progress=False)
    record = json.loads((out / "comparison.json").read_text())["methods"]["bank_profile"]
    assert not record["flown"] and record["reason"] == runner.INTERRUPTED
    rows = (out / "bank_profile" / "samples.jsonl").read_text().splitlines()
    assert len(rows) == 1
    monkeypatch.setattr(runner, "run_campaign", real)
    runner.run_comparison(comp, runs=2, out_dir=str(out), seed=7, workers=1, progress=False)
    record = json.loads((out / "comparison.json").read_text())["methods"]["bank_profile"]
    assert record["flown"] and "reason" not in record
    resumed = (out / "bank_profile" / "samples.jsonl").read_text().splitlines()
    assert len(resumed) == 2 and resumed[0] == rows[0]


def test_the_footprint_zoom_shows_the_acceptance_region_or_the_successful_cluster():
    """The zoom panel repeats nothing: three times the distance criterion when the spread is wider
    than twice that; else 1.2 x the successful samples' 90th-percentile offset; without a
    criterion a tenth of the spread."""
    from drake_entry.comparison.report import footprint_zoom

    assert footprint_zoom(500.0, 10.0, [1.0, 2.0]) == (30.0, "zoom on the acceptance region")
    offsets = list(np.linspace(0.1, 10.0, 100))  # SHEFEX-like: every sample within 70 km of a 25-km ring
    half, name = footprint_zoom(70.0, 25.0, offsets)
    assert half == pytest.approx(1.2 * np.percentile(offsets, 90)) and name == "zoom on 90 % of the successful samples"
    assert footprint_zoom(70.0, 25.0, [])[0] == 75.0  # nothing successful: the acceptance region
    assert footprint_zoom(70.0, 25.0, [0.0] * 5)[0] == pytest.approx(0.025)  # never a zero-width panel
    assert footprint_zoom(200.0, None, [1.0]) == (20.0, "zoom on the centre (a tenth of the spread)")
