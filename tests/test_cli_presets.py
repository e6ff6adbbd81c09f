"""`thermofriction presets` and the "did you mean" hint for a mistyped preset (docs/cli.md#presets)."""

import tomllib

import pytest

import thermofriction as tf
from thermofriction.models import model_from_dict, preset_path
from conftest import run_cli


def test_presets_lists_every_preset_with_its_description():
    """Oracle: the PRESETS tuple and each preset file's own description (its first words)."""
    out = run_cli("presets")
    assert out.returncode == 0, out.stderr
    lines = {line.split()[0]: line for line in out.stdout.splitlines() if line.strip()}
    for name in tf.PRESETS:
        assert name in lines, name
        desc = " ".join(tomllib.loads(preset_path(name).read_text())["description"].split())
        assert " ".join(desc.split()[:4]) in lines[name]


@pytest.mark.parametrize("name", tf.PRESETS)
def test_presets_show_prints_the_model_file(name):
    """Oracle: the printed TOML is a model file that loads to the preset itself."""
    out = run_cli("presets", "show", name)
    assert out.returncode == 0, out.stderr
    assert out.stdout == preset_path(name).read_text()
    assert model_from_dict(tomllib.loads(out.stdout)) == tf.load_model(name)


@pytest.mark.parametrize("args", [("presets", "show", "li2009-model-1"), ("simulate", "li2009-modeli")])
def test_a_mistyped_preset_names_the_closest(args):
    out = run_cli(*args)
    assert out.returncode == 2
    assert "did you mean the preset 'li2009-model-i'?" in out.stderr
    assert "Traceback" not in out.stderr and len(out.stderr.strip().splitlines()) == 1


def test_a_name_far_from_every_preset_lists_them():
    out = run_cli("presets", "show", "spring-mass")
    assert out.returncode == 2
    assert "did you mean" not in out.stderr and all(name in out.stderr for name in tf.PRESETS)


def test_load_model_hint_in_python():
    with pytest.raises(tf.InputError, match=r"canudas1996: no such file \(did you mean the preset 'canudas1995'\?\)"):
        tf.load_model("canudas1996")
    with pytest.raises(tf.InputError, match=r"my-model.toml: no such file$"):  # a file name: no preset hint
        tf.load_model("my-model.toml")
