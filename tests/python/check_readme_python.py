"""The README's Python example, taken from README.md itself, prints what the README shows
("docs never lie")."""
import os
import re
import subprocess
import sys

from known import SOURCE, expect_equal


def block_after(text, marker, language):
    start = text.index(marker)
    match = re.compile(r"```" + language + r"\n(.*?)```", re.S).search(text, start)
    return match.group(1)


def test_readme_python_example():
    readme = open(os.path.join(SOURCE, "README.md"), encoding="utf-8").read()
    code = block_after(readme, "<!-- example: readme.py -->", "python")
    shown = block_after(readme, "<!-- example: readme.py output -->", "text")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    expect_equal("the README's Python example", run.stdout, shown)
