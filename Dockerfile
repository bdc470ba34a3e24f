# rockmech solver image (service side only: no Rhino dependencies).
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    NUMBA_CACHE_DIR=/tmp/numba-cache

WORKDIR /app

# Dependencies in their own layer: only the project metadata is needed to resolve them.
COPY pyproject.toml README.md ./
RUN mkdir -p shared_schema solver_service rhino_plugin \
    && touch shared_schema/__init__.py solver_service/__init__.py rhino_plugin/__init__.py \
    && pip install ".[service]" \
    && pip uninstall -y rockmech

COPY shared_schema ./shared_schema
COPY solver_service ./solver_service
COPY rhino_plugin ./rhino_plugin
COPY examples ./examples
RUN pip install --no-deps . \
    && useradd --create-home --uid 10001 rockmech

USER rockmech
ENTRYPOINT ["rockmech"]
CMD ["--help"]
