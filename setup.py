"""setup.py - `pip install .` here installs the Python package of
bindings/python: this runs its setup.py (see there)."""
import os
import runpy

runpy.run_path(os.path.join(os.path.dirname(os.path.abspath(__file__)), "bindings", "python",
                            "setup.py"), run_name="__main__")
