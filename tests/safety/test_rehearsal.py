"""``aeroexec rehearse``: a campaign on every core and on a Dask LocalCluster, the same results for the same seeds,
a mission built to fail in strong wind failing in the windy runs, a report with the worst runs."""

from __future__ import annotations

from aeroexec.cli.main import main
from aeroexec.rehearsal import Variation, fly_dask, fly_local, seeds

WINDY = """<root BTCPP_format="4" main_tree_to_execute="M">
  <SafetyRules><![CDATA[
    - rule: max_wind
      never: wind(self, ?w), ?w > 8
      contingency: land
  ]]></SafetyRules>
  <BehaviorTree ID="M">
    <Sequence>
      <TAKE_OFF ALTITUDE="4"/>
      <GO_TO_POINT COORDINATES="5, 0, 4"/>
      <WAIT DURATION="10"/>
      <GO_TO_POINT COORDINATES="0, 0, 4"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_a_mission_built_to_fail_in_strong_wind_fails_in_the_windy_runs_on_cores_and_on_dask(tmp_path):
    mission = tmp_path / "windy.xml"
    mission.write_text(WINDY)
    run_seeds = seeds(8)
    local = fly_local(str(mission), run_seeds, workers=2)
    assert len({r.worker for r in local}) == 2, "both worker processes flew runs"
    for result in local:
        wind = result.variation.wind_speed + 3 * result.variation.wind_gust
        calm = result.variation.wind_speed + 3 * result.variation.wind_gust < 8 and result.variation.link_loss is None
        if result.variation.wind_speed > 9:
            assert not result.success and [e["rule"] for e in result.rules] == ["max_wind"], result
        elif calm:
            assert result.success, (wind, result)
    assert any(r.success for r in local) and not all(r.success for r in local)
    dask = fly_dask(str(mission), run_seeds, workers=2)
    assert [(r.variation, r.status, r.duration, r.battery, r.rules) for r in dask] == [
        (r.variation, r.status, r.duration, r.battery, r.rules) for r in local]


def test_rehearse_reports_a_success_rate_and_its_worst_runs(tmp_path, capsys):
    mission = tmp_path / "windy.xml"
    mission.write_text(WINDY)
    assert main(["rehearse", str(mission), "--runs", "4", "--output", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    assert "runs completed" in out and "worst runs:" in out and "--replay" in out
    page = (tmp_path / "r" / "rehearsal.html").read_text()
    assert "data:image/png;base64," in page and "Worst runs" in page
    worst = next(r for r in range(4) if Variation.draw(r).wind_speed > 9)
    code = main(["rehearse", str(mission), "--replay", str(worst), "--output", str(tmp_path / "r")])
    assert code == 1 and (tmp_path / "r" / f"run-{worst}" / "events.jsonl").is_file()
