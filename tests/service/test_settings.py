"""Service configuration (service.settings): CURVE_VAE_* variables, lists as JSON or comma-separated, named models,
bounds, and API keys kept out of the settings' repr."""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import ValidationError

from curve_vae.service.settings import Settings


def test_settings_from_environment(monkeypatch):
    monkeypatch.setenv("CURVE_VAE_PORT", "9123")
    monkeypatch.setenv("CURVE_VAE_PROVIDERS", "cpu")
    monkeypatch.setenv("CURVE_VAE_CORS_ORIGINS", '["https://a.example"]')
    monkeypatch.setenv("CURVE_VAE_MAX_CURVES", "7")
    s = Settings()
    assert (s.port, s.providers, s.cors_origins, s.max_curves) == (9123, "cpu", ["https://a.example"], 7)


TWO = ["https://a.example", "https://b.example"]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        pytest.param("https://a.example", ["https://a.example"], id="one"),
        pytest.param(
            " https://a.example , https://b.example ,", ["https://a.example", "https://b.example"], id="commas"
        ),
        pytest.param(
            '["https://a.example", "https://b.example"]', ["https://a.example", "https://b.example"], id="json"
        ),
        pytest.param("", [], id="empty"),
    ],
)
def test_lists_are_read_as_json_or_comma_separated(monkeypatch, text, expected):
    monkeypatch.setenv("CURVE_VAE_CORS_ORIGINS", text)
    monkeypatch.setenv("CURVE_VAE_API_KEYS", text)
    s = Settings()
    assert s.cors_origins == expected and s.api_keys == expected


def test_api_keys_never_show_in_the_settings_repr():
    s = Settings(api_keys="k-secret-0123456789", cors_origins="https://a.example")
    assert s.api_keys == ["k-secret-0123456789"]
    assert "k-secret" not in repr(s) and "k-secret" not in str(s) and "https://a.example" in repr(s)


@pytest.mark.parametrize("name", ["default", "paper"])
def test_a_shipped_models_name_is_its_directory(name):
    from curve_vae.inference.model.shipped import SHIPPED

    expected = SHIPPED if name == "default" else SHIPPED / name
    assert Settings(model_dir=name).model_dir.resolve() == expected.resolve()
    assert Settings(model_dir="some/dir").model_dir == Path("some/dir")


@pytest.mark.parametrize(
    ("field", "value"),
    [
        pytest.param("port", 65536, id="port-over-65535"),
        pytest.param("port", -1, id="port-negative"),
        pytest.param("workers", -1, id="workers-negative"),
        pytest.param("max_points", 3, id="max-points-under-4"),
        pytest.param("max_body_bytes", 1023, id="body-limit-under-1k"),
        pytest.param("micro_batch_wait_ms", 1000.5, id="wait-over-1s"),
        pytest.param("providers", "tpu", id="unknown-provider"),
        pytest.param("log_level", "loud", id="unknown-log-level"),
        pytest.param("placement", "nearest", id="unknown-placement"),
    ],
)
def test_values_out_of_bounds_are_refused_naming_the_field(field, value):
    with pytest.raises(ValidationError) as err:
        Settings(**{field: value})
    assert [e["loc"] for e in err.value.errors()] == [(field,)]


def test_settings_are_frozen_and_read_from_the_environment_once(monkeypatch):
    from curve_vae.service.settings import get_settings

    get_settings.cache_clear()
    try:
        monkeypatch.setenv("CURVE_VAE_MAX_CURVES", "11")
        first = get_settings()
        monkeypatch.setenv("CURVE_VAE_MAX_CURVES", "12")
        assert get_settings() is first and first.max_curves == 11
        with pytest.raises(ValidationError):
            first.max_curves = 5  # type: ignore[misc]
    finally:
        get_settings.cache_clear()
