# rockmech REST solver service (FastAPI + uvicorn). Service only: no Rhino libraries. The
# /api/v1/constants endpoint reads .3dm scenes and answers 501 in this image unless it is
# built with --build-arg EXTRAS=service,geometry (adds rhino3dm, trimesh, manifold3d).
FROM python:3.11-slim

ARG EXTRAS=service
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
# change to the sources does not reinstall them. Versions come from pyproject.toml's ranges
# (ghhops-server is pinned there), hence no pins on this line.
COPY pyproject.toml README.md ./
# hadolint ignore=DL3013
RUN mkdir -p shared_schema solver_service rhino_plugin \
    && touch shared_schema/__init__.py solver_service/__init__.py rhino_plugin/__init__.py \
    && pip install ".[${EXTRAS}]" \
    && pip uninstall -y rockmech \
    && rm -rf shared_schema solver_service rhino_plugin build ./*.egg-info

COPY shared_schema ./shared_schema
COPY solver_service ./solver_service
COPY rhino_plugin ./rhino_plugin
RUN pip install --no-deps . \
    && rm -rf build ./*.egg-info \
    && useradd --create-home --uid 10001 --user-group rockmech

USER 10001
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=5s --start-period=60s --retries=3 \
    CMD ["python", "-c", "import os, urllib.request; urllib.request.urlopen('http://127.0.0.1:' + os.environ.get('ROCKMECH_PORT', '8000') + '/api/v1/health', timeout=4)"]
ENTRYPOINT ["rockmech"]
CMD ["serve"]
