"""FNPEG: the fully numerical predictor-corrector entry guidance of Lu (2014), the field's
baseline (docs/methods/fnpeg.md)."""

__all__ = ["corrector", "law", "method", "onboard", "predictor", "spec"]
