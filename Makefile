# lipclock: `make run` and `make test` each set everything up on a fresh machine first.
SHELL := /bin/bash
VENV ?= .venv
PY := $(VENV)/bin/python
PIP := $(VENV)/bin/pip
STAMP := $(VENV)/.installed
DEB_PACKAGES := sox espeak-ng libespeak-ng1 flite chromium gcc libc6-dev python3-dev python3-venv
# Tools checked by command rather than by package (command:package), so that a Node.js from
# elsewhere (nodesource, nvm) counts as present: npm installs three.js for the 3-D example.
DEB_COMMANDS := node:nodejs npm:npm
HOST ?= 127.0.0.1
PORT ?= 8000
# three.js for the 3-D avatar example: pinned in package.json/package-lock.json, installed by
# npm ci and copied into client/vendor/ (gitignored), where the server serves it at
# /client/vendor/three.module.js. No CDN at run time.
THREE := node_modules/three
VENDOR := client/vendor

.PHONY: setup system-deps run test lint bench clean

setup: system-deps $(STAMP) $(VENDOR)/three.module.js

# Debian packages the tests and benchmarks use: sox/espeak-ng/flite as peers and
# audio tools, chromium for the real-browser client tests, nodejs/npm for three.js;
# gcc, libc6-dev and python3-dev (Python.h) to compile lipclock._kernels, python3-venv
# for the venv.
# Skipped when present.
system-deps:
	@missing=""; for p in $(DEB_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	for cp in $(DEB_COMMANDS); do command -v $${cp%%:*} >/dev/null || missing="$$missing $${cp#*:}"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	fi

# The C kernels (lipclock._kernels) are compiled by the editable install, so editing
# them reinstalls too.
$(STAMP): pyproject.toml setup.py $(wildcard server/lipclock/csrc/*.[ch])
	test -x $(PY) || python3 -m venv $(VENV)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q -e '.[dev]'
	touch $(STAMP)

# three.module.js imports its siblings (three.core.js since r170): copy those it names too.
$(VENDOR)/three.module.js: package.json package-lock.json
	npm ci --no-audit --no-fund --loglevel=error
	mkdir -p $(VENDOR)
	cp $(THREE)/build/three.module.js $(VENDOR)/
	cp $(THREE)/LICENSE $(VENDOR)/three.LICENSE
	for f in $$(grep -oE "from '\./[^']+'" $(THREE)/build/three.module.js | sed -E "s|from '\./(.*)'|\1|" | sort -u); do \
	  cp $(THREE)/build/$$f $(VENDOR)/; done
	touch $@

run: setup
	$(VENV)/bin/lipclock serve --host $(HOST) --port $(PORT)

test: setup
	$(VENV)/bin/python -m pytest -q

lint: setup
	$(VENV)/bin/ruff check server tests bench
	$(VENV)/bin/mypy

bench: setup
	for b in bench/bench_*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info server/*.egg-info node_modules $(VENDOR) server/lipclock/_kernels.*.so
