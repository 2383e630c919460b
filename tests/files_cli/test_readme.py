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
