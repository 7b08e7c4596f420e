# Two commands: `make demo` runs the trail mission (topside, USV, 4 AUVs) on embedded defaults (`make demo
# MISSION=usv`: the USV mission alone); every platform logs (goby-logger, moos-logger) and the demo ends by printing
# where the logs are and the command that exports them to MCAP (docs/logging.md); `make test` passes the tests.
# Each creates its own virtual environment in .venv on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin

.PHONY: demo test bench protos interfaces lint clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --upgrade --quiet pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test,demo,lint,log]'
	touch $@

MISSION ?= trail

demo: $(VENV)/.installed
	@case "$(MISSION)" in trail|usv) ;; *) echo "MISSION must be trail or usv, not '$(MISSION)'" >&2; exit 2;; esac
	$(BIN)/python -m launch.$(MISSION).demo $(DEMO_ARGS)

test: $(VENV)/.installed
	$(BIN)/python -m pytest -q

bench: $(VENV)/.installed
	$(BIN)/python -m bench

protos: $(VENV)/.installed
	$(BIN)/python -m tools.generate_protos

interfaces: $(VENV)/.installed
	$(BIN)/goby-interfaces generate --all
	$(BIN)/goby-interfaces visualize docs/interfaces/usv_deployment.yml --outdir docs/interfaces --no-disconnected --format svg
	$(BIN)/python -m launch.trail.deployment 4
	$(BIN)/goby-interfaces visualize docs/interfaces/trail_deployment.yml --outdir docs/interfaces --no-disconnected --format svg

lint: $(VENV)/.installed
	$(BIN)/ruff check .
	$(BIN)/mypy

clean:
	rm -rf $(VENV) build *.egg-info
