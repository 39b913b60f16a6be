# asymslide: the web app in a container (docs/getting-started.md, "Docker"). Needs BuildKit (Docker >= 23: the default;
# Docker 20.10: DOCKER_BUILDKIT=1).
#   docker build -t asymslide .
#   docker run -d --name asymslide -p 5006:5006 -v "$PWD/atlases:/atlases" asymslide
# The base image is a build argument, e.g. a locally built one on a machine without a registry
# (.ci/docker-smoke: --build-arg BASE_IMAGE=asymslide-base:bookworm); it must provide python3 (3.11, as the lock).
ARG BASE_IMAGE=python:3.11.11-slim-bookworm

FROM ${BASE_IMAGE} AS base
# PYTHONSAFEPATH: no working directory on sys.path, so only the installed packages are ever imported
ENV PYTHONUNBUFFERED=1 \
    PYTHONDONTWRITEBYTECODE=1 \
    PYTHONSAFEPATH=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PIP_ROOT_USER_ACTION=ignore \
    VIRTUAL_ENV=/opt/asymslide \
    PATH=/opt/asymslide/bin:$PATH
# the app's virtual environment, without pip: pip runs from the tools stage (--python), so neither pip nor
# setuptools ends up in the image
RUN python3 -m venv --without-pip "$VIRTUAL_ENV"

# --- pip, for the stages below (a venv: the official image and a Debian base alike; Debian's python3 has no pip) --
FROM base AS tools
RUN python3 -m venv /opt/tools

# --- the wheel, built from the source tree; neither leaves this stage -------------------------------------------
FROM tools AS wheel
WORKDIR /src
COPY pyproject.toml README.md ./
COPY model/ model/
COPY app/ app/
COPY atlas/ atlas/
COPY asymslide/ asymslide/
COPY static/ static/
COPY docs/physics.md docs/physics.md
RUN /opt/tools/bin/pip wheel --no-cache-dir --no-deps --wheel-dir /dist .

# --- the dependencies -----------------------------------------------------------------------------------------------
FROM base AS deps
SHELL ["/bin/bash", "-o", "pipefail", "-c"]
# binutils (strip) is a build tool of this stage only: the image gets the result, not the tool
# hadolint ignore=DL3008
RUN apt-get update \
    && apt-get install -y --no-install-recommends binutils \
    && rm -rf /var/lib/apt/lists/*
# the dependencies of asymslide[app] at the versions of requirements.lock (the requirements are read from
# pyproject.toml): rebuilt only when pyproject.toml or the lock change, not when the code does. Left out of the image
# (~170 MB, none of it used at run time): the packages' own test suites, JavaScript source maps, TypeScript and Python
# type stubs, example notebooks. Compiled libraries lose their symbol tables and debugging sections (~70 MB) where
# the stripped copy still loads (vendored *.libs are left alone: stripping those patched by auditwheel breaks them)
RUN --mount=type=bind,from=tools,source=/opt/tools,target=/opt/tools \
    --mount=type=bind,source=pyproject.toml,target=/tmp/lock/pyproject.toml \
    --mount=type=bind,source=requirements.lock,target=/tmp/lock/requirements.lock \
    --mount=type=cache,target=/root/.cache/pip \
    python -c "import tomllib; p = tomllib.load(open('/tmp/lock/pyproject.toml', 'rb'))['project']; \
x = p['optional-dependencies']; \
print(*(r for r in p['dependencies'] + x['atlas'] + x['app'] if not r.startswith('asymslide')), sep='\n')" \
       > /tmp/requirements.txt \
    && /opt/tools/bin/pip --python "$VIRTUAL_ENV/bin/python" install \
       --constraint /tmp/lock/requirements.lock --requirement /tmp/requirements.txt \
    && rm /tmp/requirements.txt \
    && find "$VIRTUAL_ENV/lib" -depth -type d -path '*/site-packages/*' -name tests -exec rm -r {} + \
    && find "$VIRTUAL_ENV/lib" -type f \( -name '*.js.map' -o -name '*.d.ts' -o -name '*.pyi' -o -name '*.ipynb' \) \
       -delete \
    && find "$VIRTUAL_ENV/lib" -type f -name '*.so*' -not -path '*.libs/*' | while read -r lib; do \
         if strip --strip-unneeded -o "$lib.stripped" "$lib" \
            && python -c 'import ctypes, sys; ctypes.CDLL(sys.argv[1])' "$lib.stripped" 2>/dev/null; \
         then mv "$lib.stripped" "$lib"; else rm -f "$lib.stripped"; fi; \
       done

# --- the image ---------------------------------------------------------------------------------------------------
FROM base
COPY --from=deps /opt/asymslide /opt/asymslide

# the project's wheel (nothing else is installed by it: pip check fails on anything missing or not as locked)
RUN --mount=type=bind,from=tools,source=/opt/tools,target=/opt/tools \
    --mount=type=bind,from=wheel,source=/dist,target=/tmp/dist \
    --mount=type=bind,source=requirements.lock,target=/tmp/lock/requirements.lock \
    /opt/tools/bin/pip --python "$VIRTUAL_ENV/bin/python" install --no-cache-dir \
       --constraint /tmp/lock/requirements.lock "$(ls /tmp/dist/asymslide-*.whl)[app]" \
    && /opt/tools/bin/pip --python "$VIRTUAL_ENV/bin/python" check

# the app user, the atlas directory it owns, and numba's cache of every kernel the app calls, compiled now by that
# user (a fresh container loads them in seconds instead of compiling them at its first page)
ENV ASYMSLIDE_ATLAS_DIR=/atlases \
    NUMBA_CACHE_DIR=/opt/asymslide-numba-cache
RUN groupadd --gid 10001 asymslide \
    && useradd --uid 10001 --gid 10001 --create-home --shell /usr/sbin/nologin asymslide \
    && install -d -o 10001 -g 10001 -m 0755 /atlases "$NUMBA_CACHE_DIR" \
    && setpriv --reuid=10001 --regid=10001 --clear-groups -- asymslide warmup \
    && python -c "from asymslide import app, atlas, model; assert all('/site-packages/asymslide/' in m.__file__ for m in (app, atlas, model))"

COPY --chmod=0755 docker/entrypoint.sh /usr/local/bin/asymslide-entrypoint

WORKDIR /home/asymslide
# PORT: where the server listens; ALLOWED_ORIGIN: the host[:port] people type in their browser; NUM_PROCS: server
# processes (at most one per core)
ENV PORT=5006 \
    ALLOWED_ORIGIN=localhost:5006 \
    NUM_PROCS=2
EXPOSE 5006

# the image has no curl: ask the liveness endpoint with Python's standard library
HEALTHCHECK --interval=30s --timeout=5s --start-period=30s --retries=3 \
    CMD ["python", "-c", "import os, urllib.request; urllib.request.urlopen(f'http://127.0.0.1:{os.environ[\"PORT\"]}/liveness', timeout=4)"]

# the entrypoint starts as root only to hand a mounted atlas folder to the app user, then drops to that user
# (docker/entrypoint.sh); sh -c only expands the variables; exec makes the launcher PID 1: on docker stop (SIGTERM)
# it stops every panel process, workers included, and exits 0
ENTRYPOINT ["asymslide-entrypoint"]
CMD ["sh", "-c", "exec asymslide serve --port \"$PORT\" --address 0.0.0.0 --liveness --num-procs \"$NUM_PROCS\" --allow-websocket-origin \"$ALLOWED_ORIGIN\""]
