"""An ONNX image-text model the user names (CLIP-style): image embedding against prompt embeddings.

The model file has two inputs, an image (``1 x 3 x S x S`` float, RGB scaled to 0..1 and normalised with CLIP's
mean and standard deviation) and a text (``1 x L`` int64 tokens), and two outputs, the image's and the text's
embedding (``1 x D`` each), recognised by name (``image...`` / ``text...``). Prompts are tokenised by their UTF-8
bytes (byte + 1, zero-padded to ``L``): a model exported with another tokenizer needs its prompts in that form.
The scores are the softmax over the prompts of the scaled cosine similarities.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

MEAN = np.array([0.48145466, 0.4578275, 0.40821073], dtype=np.float32)
STD = np.array([0.26862954, 0.26130258, 0.27577711], dtype=np.float32)


class ImageTextModelError(RuntimeError):
    """The image-text model cannot be loaded or does not have the expected inputs and outputs."""


def byte_tokens(text: str, length: int) -> np.ndarray:
    """``1 x length`` int64 tokens: each UTF-8 byte + 1, zero-padded (cut at ``length``)."""
    data = np.frombuffer(text.encode("utf-8"), dtype=np.uint8)[:length].astype(np.int64) + 1
    tokens = np.zeros((1, length), dtype=np.int64)
    tokens[0, : data.size] = data
    return tokens


@dataclass
class ImageTextModel:
    """A loaded image-text model: its session, input and output names, image size and text length."""

    session: Any
    image_input: str
    text_input: str
    image_output: str
    text_output: str
    size: int
    length: int
    temperature: float = 100.0

    @classmethod
    def load(cls, path: Path) -> ImageTextModel:
        """Load the model; raises ImageTextModelError naming what is missing."""
        if not Path(path).is_file():
            raise ImageTextModelError(f"no image-text model file at {path}")
        try:
            import onnxruntime

            session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
        except Exception as error:  # onnxruntime's own errors for a damaged or unsupported model
            raise ImageTextModelError(f"the image-text model {path} cannot be loaded: {error}") from None
        inputs = {i.name: i for i in session.get_inputs()}
        outputs = [o.name for o in session.get_outputs()]
        image = [n for n, i in inputs.items() if len(i.shape) == 4]
        text = [n for n, i in inputs.items() if len(i.shape) == 2 and "int" in i.type]
        image_out = [n for n in outputs if n.lower().startswith("image")]
        text_out = [n for n in outputs if n.lower().startswith("text")]
        if len(image) != 1 or len(text) != 1 or len(image_out) != 1 or len(text_out) != 1:
            raise ImageTextModelError(
                f"{path}: an image-text model needs one 4-D image input, one 2-D integer text input and outputs "
                f"named image... and text...; it has inputs {sorted(inputs)} and outputs {outputs}"
            )
        size, length = inputs[image[0]].shape[2], inputs[text[0]].shape[1]
        if not isinstance(size, int) or not isinstance(length, int):
            raise ImageTextModelError(f"{path}: the image size and text length must be fixed")
        return cls(session, image[0], text[0], image_out[0], text_out[0], size, length)

    def _embed(self, image: np.ndarray, text: str) -> tuple[np.ndarray, np.ndarray]:
        resized = cv2.resize(image, (self.size, self.size), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
        tensor = ((resized - MEAN) / STD).transpose(2, 0, 1)[None]
        feeds = {self.image_input: tensor, self.text_input: byte_tokens(text, self.length)}
        image_embedding, text_embedding = self.session.run([self.image_output, self.text_output], feeds)
        return np.asarray(image_embedding, np.float64).reshape(-1), np.asarray(text_embedding, np.float64).reshape(-1)

    def scores(self, image: np.ndarray, prompts: Sequence[str]) -> list[float]:
        """The probability of each prompt describing the RGB uint8 ``image`` (softmax of scaled cosines)."""
        if image.ndim != 3 or image.shape[2] != 3 or min(image.shape[:2]) < 2:
            raise ValueError(f"the image-text model needs an RGB image, got shape {image.shape}")
        cosines = []
        for prompt in prompts:
            a, b = self._embed(image, prompt)
            cosines.append(float(a @ b / max(np.linalg.norm(a) * np.linalg.norm(b), 1e-12)))
        logits = self.temperature * np.array(cosines)
        weights = np.exp(logits - logits.max())
        return [float(w) for w in weights / weights.sum()]
