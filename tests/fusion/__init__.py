"""Tests of hypothesis fusion, identity across frames, the belief store and answers."""
