"""Executes a Jupyter notebook with jupyter-nbconvert (as CI does) and checks the result: every
code cell ran without an error and the notebook drew figures.

    run_notebook.py JUPYTER_NBCONVERT NOTEBOOK OUTPUT_DIR

The executed notebook is OUTPUT_DIR/<name>.ipynb; exit status 1 with the reason otherwise.
Its cells run in the notebook's own directory (nbconvert's default), as in Jupyter.
The notebook's own assert cells check its numbers (a failed assert is an error here).
"""

import json
import os
import subprocess
import sys


def main(nbconvert, notebook, output_dir):
    notebook, output_dir = os.path.abspath(notebook), os.path.abspath(output_dir)
    os.makedirs(output_dir, exist_ok=True)
    # The kernel runs in the notebook's directory: a relative PYTHONPATH would point elsewhere.
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        os.path.abspath(p) for p in env.get("PYTHONPATH", "").split(os.pathsep) if p)
    done = subprocess.run(
        [nbconvert, "--to", "notebook", "--execute", "--output-dir", output_dir,
         "--ExecutePreprocessor.timeout=120", notebook],
        env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        print(done.stdout + done.stderr, file=sys.stderr)
        return f"jupyter-nbconvert failed with exit status {done.returncode}"
    with open(os.path.join(output_dir, os.path.basename(notebook)), encoding="utf-8") as f:
        executed = json.load(f)
    code = [c for c in executed["cells"] if c["cell_type"] == "code"]
    outputs = [o for c in code for o in c.get("outputs", [])]
    errors = [o for o in outputs if o["output_type"] == "error"]
    if errors:
        return f"a cell raised {errors[0]['ename']}: {errors[0]['evalue']}"
    not_run = [i for i, c in enumerate(code) if c.get("execution_count") is None]
    if not_run:
        return f"code cells {not_run} did not run"
    figures = sum("image/png" in o.get("data", {}) for o in outputs)
    if figures < 2:
        return f"the notebook drew {figures} figure(s), expected at least 2"
    print(f"{notebook}: {len(code)} code cells ran, {figures} figures")
    return None


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    problem = main(*sys.argv[1:])
    if problem:
        sys.exit(f"run_notebook: {problem}")
