"""``robokudo serve``: one long-lived answering service behind the rosbridge v2 protocol over WebSocket."""
