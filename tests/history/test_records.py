"""The records the store gives back: a queued message's JSON."""

from monitor.history.records import Attachment, Message


def test_a_message_keeps_its_attachment_bytes_through_json():
    msg = Message("s", "t", "h", ("b",), (Attachment("trend.png", b"\x89PNG\x00\xff"),))
    assert Message.from_json(msg.to_json()) == msg


def test_a_message_queued_with_a_path_by_an_older_version_goes_without_it():
    old = '{"subject": "s", "text": "t", "html": "h", "blocks": [], "attachments": ["/srv/r/j01/trend.png"]}'
    assert Message.from_json(old) == Message("s", "t", "h")
