# rockmech REST solver service (FastAPI + uvicorn). The default image serves every endpoint,
# /api/v1/constants (.3dm scenes: rhino3dm, trimesh, manifold3d, shapely) included. Build
# with --build-arg EXTRAS=service for a slimmer image without the geometry libraries: there
# /api/v1/constants answers 501 with the install line of the missing extra.
FROM python:3.11-slim

ARG EXTRAS=service,geometry
ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    NUMBA_CACHE_DIR=/tmp/numba-cache \
    MPLCONFIGDIR=/tmp/matplotlib \
    ROCKMECH_HOST=0.0.0.0 \
    ROCKMECH_PORT=8000

WORKDIR /app

# Dependencies in their own layer: only the project metadata is needed to resolve them, so a
# change to the sources does not reinstall them. The package folders pyproject.toml lists are
# created empty for that install and removed after it. Versions come from pyproject.toml's
# ranges (ghhops-server is pinned there), hence no pins on this line.
COPY pyproject.toml README.md LICENSE ./
COPY shared_schema/version.py ./shared_schema/version.py
# hadolint ignore=DL3013
RUN python -c "import pathlib, tomllib; t = tomllib.load(open('pyproject.toml', 'rb'))['tool']['setuptools']; [pathlib.Path(t['package-dir'].get(p, p.replace('.', '/'))).mkdir(parents=True, exist_ok=True) for p in t['packages']]" \
    && pip install ".[${EXTRAS}]" \
    && pip uninstall -y rockmech \
    && rm -rf rockmech shared_schema solver_service rhino_plugin examples build ./*.egg-info

COPY rockmech ./rockmech
COPY shared_schema ./shared_schema
COPY solver_service ./solver_service
COPY rhino_plugin ./rhino_plugin
COPY examples ./examples
RUN pip install --no-deps . \
    && rm -rf build ./*.egg-info \
    && useradd --create-home --uid 10001 --user-group rockmech

USER 10001
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=5s --start-period=60s --retries=3 \
    CMD ["python", "-c", "import os, urllib.request; urllib.request.urlopen('http://127.0.0.1:' + os.environ.get('ROCKMECH_PORT', '8000') + '/api/v1/health', timeout=4)"]
ENTRYPOINT ["rockmech"]
CMD ["serve"]
