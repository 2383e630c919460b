"""The README's Python API example runs as written."""

import re

import matplotlib

from repo import REPO_ROOT


def test_readme_python_api_block_runs(tmp_path, monkeypatch):
    matplotlib.use("Agg")
    text = (REPO_ROOT / "README.md").read_text()
    section = text.split("## Python API", 1)[1]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(block, "README.md", "exec"), namespace)
    assert (tmp_path / "pendulum.nc").exists()
    assert namespace["results"].success


def test_readme_model_file_blocks_are_current(tmp_path):
    """The model-file section's TOML blocks are in today's syntax: the pendulum loads with no
    deprecation, and the [[elements]] excerpt is the shipped slider-crank's."""
    import tomllib
    import warnings

    from drivedyn.config import load_model, shipped_models

    text = (REPO_ROOT / "README.md").read_text()
    section = text.split("## Model files and the command line", 1)[1].split("\n## ", 1)[0]
    pendulum, excerpt = re.findall(r"```toml\n(.*?)```", section, re.S)[:2]
    path = tmp_path / "pendulum.toml"
    path.write_text(pendulum)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        model = load_model(path)
    assert model.meta["notes"] == []
    assert [type(e).__name__ for e in model.spec.elements] == ["Hinge"]
    shipped = tomllib.loads(shipped_models()["slider_crank"].read_text())["elements"]
    for entry in tomllib.loads(excerpt)["elements"]:
        assert entry in shipped
