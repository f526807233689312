# The two commands of the README, and a few helpers.  Each target sets up
# what is missing first (scripts/setup.sh), so a fresh clone needs nothing else.
PY := .venv/bin/python
TTT := .venv/bin/ttt-sm
# Test workers (pytest-xdist): one per CPU, at most 4.  `make test JOBS=0` runs in this process alone.
# The 15 slowest tests are listed at the end (where the suite's 8 minutes go).
JOBS ?= auto
PYTEST := $(PY) -m pytest -q -n $(JOBS) --maxprocesses 4 --dist worksteal --durations 15

.PHONY: setup play test gui screenshots soak fuzz lint bench tune firmware docs clean

setup:
	@sh scripts/setup.sh

play: setup
	$(TTT) play

test: setup
	$(PYTEST)

gui: setup
	$(TTT) gui --open

# The pictures of docs/gui.md, taken in Chromium from a live cockpit.
screenshots: setup
	TTT_SM_SCREENSHOTS=docs/img $(PY) -m pytest -q tests/web/test_gui_screenshots.py tests/web/test_game_page.py tests/web/test_operate_page.py \
		tests/web/test_safety_reset_page.py -k "guide or whole_game or circle or blocked_drive"

soak: setup
	$(PYTEST) -m soak; rc=$$?; [ $$rc -eq 5 ] && echo "no soak tests" || exit $$rc

fuzz: setup
	TTT_SM_FUZZ_RANDOM=1 $(PYTEST) -m soak -k fuzz

lint: setup
	.venv/bin/ruff check src tests tools
	.venv/bin/mypy

# Every generated file of the repository: charts/, docs/architecture.md, the firmware's layout.h, structs.h,
# protocol.h and the reference board's arm_board.h
# (tools/docs.py, a development tool: not in the installed package).  `make docs CHECK=1` only checks.
docs: setup
	$(PY) -m tools.docs $(if $(CHECK),check,export)

bench: setup
	$(TTT) bench

tune: setup
	$(TTT) tune

# The firmware's portable C (firmware/), built with the system compiler as the tests
# load it, both precisions, every warning an error (flags: ttt_sm.hardware.firmware),
# after checking its generated headers are what their tables make (layout.h: twin/layout.py,
# structs.h: hardware/structs.py, protocol.h: hardware/link/protocol.py, arm_board.h: data/arm.toml).
firmware: setup
	$(PY) -m ttt_sm.hardware.generate --check
	$(PY) -m ttt_sm.hardware.firmware out/firmware

clean:
	rm -rf .venv out .pytest_cache
