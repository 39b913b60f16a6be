# asymslide: the Panel app in a container.
#   docker build -t asymslide .
#   docker run -p 5006:5006 -e ALLOWED_ORIGIN=localhost:5006 asymslide
FROM python:3.11.11-slim-bookworm

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    NUMBA_CACHE_DIR=/tmp/numba_cache \
    ALLOWED_ORIGIN=localhost:5006 \
    NUM_PROCS=2

WORKDIR /srv/asymslide

COPY pyproject.toml README.md ./
COPY model/ model/
COPY app/ app/
COPY asymslide/ asymslide/
COPY static/ static/

# the same install as the README's, then an unprivileged user to run the server
RUN pip install --no-cache-dir . \
    && groupadd --gid 10001 asymslide \
    && useradd --create-home --uid 10001 --gid 10001 --shell /usr/sbin/nologin asymslide

# numeric, so the host (and runAsNonRoot checks) can tell it is not root
USER 10001:10001

EXPOSE 5006

# slim has no curl: ask the liveness endpoint with Python's standard library
HEALTHCHECK --interval=30s --timeout=5s --start-period=30s --retries=3 \
    CMD ["python", "-c", "import urllib.request; urllib.request.urlopen('http://127.0.0.1:5006/liveness', timeout=4)"]

# sh -c only to expand ALLOWED_ORIGIN and NUM_PROCS (server processes: at most the container's cores);
# exec makes the launcher PID 1: on docker stop (SIGTERM) it stops every panel process, workers included
CMD ["sh", "-c", "exec asymslide serve --port 5006 --address 0.0.0.0 --liveness --num-procs \"$NUM_PROCS\" --allow-websocket-origin \"$ALLOWED_ORIGIN\""]
