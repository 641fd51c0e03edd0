"""The package list, derived rather than kept by hand: every package directory under drake_entry/
(a new method folder needs no entry here) and the two that pyproject's package-dir installs inside
it (systems/ -> drake_entry.systems, diagrams/ -> drake_entry.diagrams). Everything else about the
build is in pyproject.toml."""
from setuptools import find_namespace_packages, setup

setup(packages=find_namespace_packages(include=["drake_entry", "drake_entry.*"], exclude=["*.__pycache__"])
      + ["drake_entry.systems", "drake_entry.diagrams"])
