"""The paper's storage scenario on one running engine: ``robokudo scenario storage`` (see :mod:`.mission`)."""
