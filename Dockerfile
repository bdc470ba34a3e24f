# rockmech REST solver service (FastAPI + uvicorn). The default image serves every endpoint:
# .3dm scenes (geometry), the assessment's HTML page (report), .xlsx tables (tables). Build
# with --build-arg PDF=chromium to add a headless Chromium, so that POST /api/v1/assess
# answers format "pdf" too (without it: 501 naming the missing browser); --build-arg
# EXTRAS=service builds a slimmer image in which the endpoints of the missing extras answer
# 501 with their install line.
#
# Reproducible: the base image is pinned by digest (python:3.11-slim; refresh it with
# `docker buildx imagetools inspect python:3.11-slim`), and every Python package by
# docker/requirements.lock (pip constraints; tests/service/test_dockerfile.py --lock).
FROM python:3.11-slim@sha256:9c900dea9e8fb7e16277c179b555cc72d29a352dbc33cff48ad5a0412fd5bfc7

ARG EXTRAS=all
ARG PDF=""
# NUMBA_CPU_NAME=generic: the kernels compiled while the image is built run on any x86-64 or
# ARM64 host (numba's cache otherwise holds code for the build machine's processor only).
ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    NUMBA_CACHE_DIR=/opt/rockmech/numba-cache \
    NUMBA_CPU_NAME=generic \
    MPLCONFIGDIR=/tmp/matplotlib \
    ROCKMECH_HOST=0.0.0.0 \
    ROCKMECH_PORT=8000

# A headless browser for the PDF only when asked for (it adds about 300 MB). Debian's
# chromium follows the pinned base image's release.
# hadolint ignore=DL3008
RUN if [ "$PDF" = "chromium" ]; then \
        apt-get update \
        && apt-get install -y --no-install-recommends chromium \
        && rm -rf /var/lib/apt/lists/*; \
    fi

WORKDIR /app

# Dependencies in their own layer: only the project metadata and the lock file are needed to
# resolve them, so a change to the sources does not reinstall them. The package folders
# pyproject.toml lists are created empty for that install and removed after it.
COPY pyproject.toml README.md LICENSE ./
COPY docker/requirements.lock ./docker/requirements.lock
COPY shared_schema/version.py ./shared_schema/version.py
RUN python -c "import pathlib, tomllib; t = tomllib.load(open('pyproject.toml', 'rb'))['tool']['setuptools']; [pathlib.Path(t['package-dir'].get(p, p.replace('.', '/'))).mkdir(parents=True, exist_ok=True) for p in t['packages']]" \
    && pip install -c docker/requirements.lock ".[${EXTRAS}]" \
    && pip uninstall -y rockmech \
    && rm -rf rockmech shared_schema cad_maths solver_service rhino_plugin examples build ./*.egg-info

COPY rockmech ./rockmech
COPY shared_schema ./shared_schema
COPY cad_maths ./cad_maths
COPY solver_service ./solver_service
COPY rhino_plugin ./rhino_plugin
COPY examples ./examples
# The solver's kernels are compiled here, once, into NUMBA_CACHE_DIR: a worker of the
# service loads them in under a second when the container starts.
RUN pip install --no-deps . \
    && rm -rf build ./*.egg-info \
    && useradd --create-home --uid 10001 --user-group rockmech \
    && mkdir -p "$NUMBA_CACHE_DIR" \
    && rockmech kernels \
    && chown -R rockmech:rockmech "$NUMBA_CACHE_DIR"

USER 10001
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=5s --start-period=30s --retries=3 \
    CMD ["python", "-c", "import os, urllib.request; urllib.request.urlopen('http://127.0.0.1:' + os.environ.get('ROCKMECH_PORT', '8000') + '/api/v1/health', timeout=4)"]
ENTRYPOINT ["rockmech"]
CMD ["serve"]
