"""A planner message as OpenAI-style chat content (what litellm and llama-cpp-python both take)."""

from __future__ import annotations

from typing import Any

from eb_core.model import ImagePart, Message

__all__ = ["openai_parts"]


def openai_parts(message: Message) -> list[dict[str, Any]]:
    """The message's parts in order: ``image_url`` parts with data URLs, ``text`` parts with their text."""
    return [{"type": "image_url", "image_url": {"url": p.data_url()}} if isinstance(p, ImagePart)
            else {"type": "text", "text": p.text} for p in message.content]
