"""The one settings object of the REST service (pydantic-settings, env prefix ``ROCKMECH_``).

Every value can be set in the environment, e.g. ``ROCKMECH_COMPUTE_TIMEOUT_S=10``; ``rockmech
serve`` options override the environment. Nothing else in the service reads ``os.environ``.
"""

from __future__ import annotations

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings"]


class Settings(BaseSettings):
    """Service settings.

    Attributes
    ----------
    host : str
        Interface to bind; loopback by default, so the service is not reachable from other
        machines unless asked.
    port : int
        TCP port.
    compute_workers : int
        Compute processes; each request's computation runs in one of them.
    compute_timeout_s : float
        Compute time budget of one request [s]; past it the computation is abandoned (its
        process is ended and replaced) and the request gets 503.
    queue_timeout_s : float
        Longest wait for a free compute process [s]; past it the request gets 503.
    startup_timeout_s : float
        Time a compute process has to start (imports and warm-up) [s]; past it, it is
        started again with twice the time (one log line each time; the server keeps
        running, and ``/health`` says ``starting`` until every process is ready).
    max_body_bytes : int
        Largest request body [bytes], uploads included; larger bodies get 413.
    max_samples : int
        Most record samples, frequencies or periods in one request; more gets 422.
    max_mechanisms : int
        Most mechanisms in one request (constants file or spec); more gets 422.
    max_scales : int
        Most scale factors in one request; more gets 422.
    max_answer_bytes : int
        Largest answer a request may ask for [bytes], estimated before computing; more gets
        422.
    allowed_hosts : list of str
        Host names the service answers to (the ``Host`` header, port ignored); others get
        400. Default: the loopback names. Add the name clients use for a deployment on a
        network, or ``"*"`` for any.
    allowed_origins : list of str
        Web page origins (``scheme://host[:port]``) allowed to call the service from a
        browser, besides its own pages; others get 403. Default: none; ``"*"`` for any.
    shutdown_timeout_s : float
        On SIGTERM, longest wait for requests in flight [s]; then the compute processes
        are stopped.
    log_level : str
        uvicorn's log level.
    """

    model_config = SettingsConfigDict(env_prefix="ROCKMECH_", extra="ignore")

    host: str = "127.0.0.1"
    port: int = Field(8000, ge=0, le=65535)
    compute_workers: int = Field(2, ge=1, le=64)
    compute_timeout_s: float = Field(30.0, gt=0)
    queue_timeout_s: float = Field(60.0, gt=0)
    startup_timeout_s: float = Field(120.0, gt=0)
    max_body_bytes: int = Field(32 * 1024 * 1024, ge=1024)
    max_samples: int = Field(500_000, ge=2)
    max_mechanisms: int = Field(100, ge=1)
    max_scales: int = Field(100, ge=1)
    max_answer_bytes: int = Field(64 * 1024 * 1024, ge=1024)
    allowed_hosts: list[str] = Field(default_factory=lambda: ["localhost", "127.0.0.1", "[::1]"])
    allowed_origins: list[str] = Field(default_factory=list)
    shutdown_timeout_s: float = Field(10.0, gt=0)
    log_level: str = "warning"

    def limits(self) -> dict[str, float]:
        """Return the per-request limits and the budget, as the compute processes get them."""
        return {
            "budget_s": self.compute_timeout_s,
            "max_samples": self.max_samples,
            "max_mechanisms": self.max_mechanisms,
            "max_scales": self.max_scales,
            "max_answer_bytes": self.max_answer_bytes,
        }
