"""Installs the package the documented way into a fresh virtual environment
(`python3 -m venv --system-site-packages`, then `cmake --install <build>
--component python --prefix <venv>`) and imports it from there, with no
PYTHONPATH and from another folder (ctest: python_install).

    python3 check_install.py <cmake> <build folder>

Exits 77 (skipped) when this Python cannot make a virtual environment.
"""
import os
import subprocess
import sys
import tempfile

SCRIPT = """
import os, sys, gravcal
assert gravcal.__file__.startswith(sys.prefix), gravcal.__file__
truth, log = gravcal.simulate(seed=3, sim_hold=4)
cal = gravcal.calibrate(log)
assert cal.apply(log.accel).shape == (len(log), 3)
print(gravcal.__version__, os.path.dirname(gravcal.__file__))
"""


def main():
    cmake, build = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as folder:
        venv = os.path.join(folder, "venv")
        made = subprocess.run([sys.executable, "-m", "venv", "--system-site-packages",
                               "--without-pip", venv], capture_output=True, text=True)
        if made.returncode != 0:
            print("python_install skipped: no virtual environment: %s" % made.stderr.strip())
            return 77
        subprocess.run([cmake, "--install", build, "--component", "python", "--prefix", venv],
                       check=True, stdout=subprocess.DEVNULL)
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
        run = subprocess.run([os.path.join(venv, "bin", "python"), "-c", SCRIPT], cwd=folder,
                             env=env, capture_output=True, text=True)
        sys.stdout.write(run.stdout + run.stderr)
        return run.returncode


if __name__ == "__main__":
    sys.exit(main())
