"""The persistent belief store (SQLite), the filter a query selects beliefs with, and the answers (object
designators) drawn from it."""
