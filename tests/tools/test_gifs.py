"""tools/gifs.py: each card's GIF plays its model on a stated seed, the first of its recorded evaluation, or
the first on which a goal's evaluation succeeded; the seeds the Makefile used to type (Mario 1-1 on
1000000, 1-4 on 1000001) follow from that rule."""
from tools.docgen.data import shipped_models
from tools.gifs import gif_seed, render_command


def test_the_seed_is_the_first_success_else_the_first_seed():
    assert gif_seed({"per_episode": [{"seed": 5, "success": False}, {"seed": 6, "success": True}]}) == 6
    assert gif_seed({"per_episode": [{"seed": 5}, {"seed": 6}]}) == 5
    assert gif_seed({"seeds": "1000000..1000099"}) == 1000000


def test_every_shipped_model_has_a_render_command_of_its_own_folder():
    models = {m.slug: m for m in shipped_models()}
    assert len(models) == 17
    commands = {slug: render_command(m) for slug, m in models.items()}
    assert commands["mario_ppo_1-4"][commands["mario_ppo_1-4"].index("--seed") + 1] == "1000001"
    for slug, command in commands.items():
        assert command[command.index("--model") + 1] == models[slug].folder
        assert command[-1] == f"docs/assets/gifs/{slug}.gif"

