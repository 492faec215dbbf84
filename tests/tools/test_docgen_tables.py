"""The generated tables read what the model folders hold: a model trained ``--init-from`` another gives
what the whole chain cost, and the CSV columns are those of every shipped file, not the first one's."""
from __future__ import annotations

from tools.docgen import data as docgen_data
from tools.docgen import main as docgen


def _model(tmp_path, name, meta, header=None):
    folder = tmp_path / "saved_networks" / "mario_ppo" / name
    folder.mkdir(parents=True)
    if header:
        (folder / "rollouts.csv").write_text(header + "\n")
    return docgen_data.Model("mario_ppo", name, f"saved_networks/mario_ppo/{name}",
                             {"algo": "ppo", "kind": "ppo", "preset": "levels", "episodes": 10, **meta}, None)


def test_a_chain_of_init_from_runs_is_added_up_and_named(tmp_path, monkeypatch):
    grandparent = {"path": "saved_networks/mario_ppo/2-1", "env_steps": 1_000, "wall_seconds": 3_600.0}
    chained = _model(tmp_path, "1-3", {"env_steps": 300, "wall_seconds": 1_800.0, "init_from": {
        "path": "saved_networks/mario_ppo/2-3", "env_steps": 200, "wall_seconds": 1_800.0, "init_from": grandparent}})
    again = _model(tmp_path, "2-2", {"env_steps": 50, "wall_seconds": 360.0,
                                     "init_from": {"path": "saved_networks/mario_ppo/2-2/", "env_steps": 50,
                                                   "wall_seconds": 360.0}})
    alone = _model(tmp_path, "1-2", {"env_steps": 70, "wall_seconds": 36.0})
    assert [p["path"] for p in chained.lineage] == ["saved_networks/mario_ppo/2-3", "saved_networks/mario_ppo/2-1"]
    assert chained.from_scratch() == (1_500, 7_200.0) and alone.lineage == [] and alone.from_scratch() == (70, 36.0)
    monkeypatch.setattr(docgen_data, "shipped_models", lambda: [chained, again, alone])
    text = docgen.render("regions/shipped.md", page="docs/x.md", arg="mario_ppo")
    assert "| 300 | 10 | 1,800 s | 1,500, 2.0 h (from 2-3, 2-1) |" in text
    assert "| 50 | 10 | 360 s | 100, 720 s (from an earlier 2-2) |" in text
    assert "| 70 | 10 | 36 s | – |" in text
    monkeypatch.setattr(docgen_data, "shipped_models", lambda: [alone])  # no chain: no column
    assert "started from" not in docgen.render("regions/shipped.md", page="docs/x.md", arg="mario_ppo")


def test_csv_columns_are_those_of_every_file(tmp_path, monkeypatch):
    old = _model(tmp_path, "1-2", {}, "rollout,env_steps,loss")
    new = _model(tmp_path, "1-1", {}, "rollout,env_steps,loss,lr")
    monkeypatch.setattr(docgen_data, "REPO", tmp_path)
    monkeypatch.setattr(docgen_data, "shipped_models", lambda: [old, new])
    text = docgen.render("regions/csv-columns.md", page="docs/x.md", arg="mario_ppo")
    assert "| `rollouts.csv` | mario_ppo | ppo | `rollout`, `env_steps`, `loss`, `lr`* |" in text
    assert "in some of the shipped models' files only" in text
    monkeypatch.setattr(docgen_data, "shipped_models", lambda: [new])
    assert "*" not in docgen.render("regions/csv-columns.md", page="docs/x.md", arg="mario_ppo").replace("`", "")


def test_a_card_says_where_the_misses_ended_and_what_ended_them(tmp_path):
    """Issue 63: a level short of its bar says where it stalls. Misses by x in blocks of 100 with their cause (the
    enemy's name, a fall, the stall limit), most first; the episodes that reached the flag are not counted."""
    episodes = [{"success": True, "x_pos": 3161.0}, {"success": False, "x_pos": 2674.0, "stalled": 1.0},
                {"success": False, "x_pos": 2690.0, "stalled": 1.0}, {"success": False, "x_pos": 1734.0, "killed_by": 6.0},
                {"success": False, "x_pos": 2450.0, "killed_by": -1.0}, {"success": False, "x_pos": 2460.0}]
    model = _model(tmp_path, "1-2", {"evaluation": {"success_share": 1 / 6, "episodes": 6, "per_episode": episodes}})
    assert docgen.miss_places(model) == ("2,600-2,699: stalled 2; 1,700-1,799: Goomba 1; 2,400-2,499: fell 1; "
                                         "2,400-2,499: no cause recorded 1")
    assert docgen.miss_causes(model) == "stalled 2, Goomba 1, fell 1, no cause recorded 1"  # stalls counted too
    assert docgen.miss_causes(_model(tmp_path, "2-2", {"evaluation": {"causes": {"fell": 2}}})) == "fell 2"  # no records
    assert docgen.miss_places(_model(tmp_path, "1-3", {"evaluation": {"success_share": 1.0, "episodes": 1,
                                                                      "per_episode": episodes[:1]}})) == ""
