# Two commands for users: `make run` and `make test`. Everything they need is installed here.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test fuzz bench lint docs system-deps clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[app,test,docs,study]'
	# the solvers' compiled fills (free space and periodic), compiled once here and cached (else the first solve pays ~20-40 s)
	$(BIN)/python -c "from barymesh.mom.compiled_periodic_fill import warm_up; warm_up()"
	# the mesher's opt-in compiled loops for large meshes (BARYMESH_MESH_KERNELS=numba; a few seconds)
	$(BIN)/python -c "from barymesh.repeat.compiled import warm_up; warm_up()"
	touch $(STAMP)

# Debian packages the desktop window and its tests need (a virtual X server and Mesa's
# software OpenGL). Installed when missing and running as root; otherwise named.
system-deps:
	@bash scripts/system-deps.sh

# The gmsh wheel links X11/OpenGL libraries even when it runs headless (make bench, and
# make test: tests/test_io_gmsh.py reads our .msh files back with Gmsh).
GMSH_DEPS := libglu1-mesa libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 \
	libfontconfig1 libgomp1

run: $(STAMP) system-deps
	$(BIN)/barymesh

test: $(STAMP)
	@bash scripts/system-deps.sh $(GMSH_DEPS)
	$(BIN)/python -m pytest

# The hostile-input fuzz at 50,000 examples (make test runs 2,000): parameters, then a
# tenth as many cell documents and study specs, a twentieth of frequencies for the
# free-space solver and a fortieth for the infinite array (each test scales its own count).
# Fresh examples on every run (the "fuzz" profile); FUZZ_ARGS=--hypothesis-seed=N repeats one.
fuzz: $(STAMP)
	HYPOTHESIS_PROFILE=fuzz BARYMESH_FUZZ_EXAMPLES=50000 $(BIN)/python -m pytest -p no:xvfb -q \
		tests/test_core_properties.py tests/test_cell_properties.py tests/test_study_spec.py \
		tests/test_mom_api.py tests/test_mom_periodic_checks.py -k "hostile or any_frequency" \
		--hypothesis-show-statistics --timeout=0 $(FUZZ_ARGS)

bench: $(STAMP)
	@bash scripts/system-deps.sh $(GMSH_DEPS)
	$(BIN)/python -m pip install --quiet -e '.[app,test,bench]'
	$(BIN)/python benchmarks/mesher.py

# Mutation testing (mutmut) of the topology, the weld, the template assembly and the file
# formats, one module after the other; each mutant runs only the tests that call the function
# it changed (see [tool.mutmut] in pyproject.toml). The score and the survivors judged
# harmless are in CONTRIBUTING.md, Mutation testing. `$(BIN)/mutmut browse` shows the survivors.
MUTATE_MODULES := core.topology core.weld core.repeat.patches core.io

.PHONY: mutate
mutate: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[app,test,mutate]'
	for module in $(MUTATE_MODULES); do $(BIN)/mutmut run "$$module.*" || exit 1; done
	$(BIN)/mutmut results

# The documentation (Sphinx, docs/): warnings are errors (-W), every reference into barymesh
# must resolve (-n), and every internal link and anchor of the built HTML must resolve
# (scripts/check_html_links.py; Sphinx's linkcheck builder is for the external ones). autodoc imports the window's modules (no display needed to import them);
# the API pages are generated afresh, so a renamed module leaves no stale page behind.
docs: $(STAMP) system-deps
	rm -rf docs/api/generated
	$(BIN)/python -m sphinx -b html -W --keep-going -n docs docs/_build/html
	$(BIN)/python scripts/check_html_links.py docs/_build/html
	@echo "open docs/_build/html/index.html"

# The code is formatted by `ruff format` (line length 100, pyproject.toml); `make format` applies it.
# Then: no import circle in the core (tests/import_graph.py, grimp's graph) and mypy over
# core/ and app/ as barymesh and barymesh.app ([tool.mypy] in pyproject.toml, typecheck/).
lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python tests/import_graph.py
	$(BIN)/python -m mypy

.PHONY: format
format: $(STAMP)
	$(BIN)/ruff format .

clean:
	rm -rf $(VENV) .pytest_cache .hypothesis .mypy_cache build *.egg-info mutants docs/_build \
		docs/api/generated
