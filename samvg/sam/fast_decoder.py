"""Fast exact mask decoding for many prompts on one image (low-rank two-way transformer).

Why it is exact and fast. All prompts share the image embedding; the only per-prompt change to
the 4096 image tokens comes from the image->token attentions, whose output is
``A @ U``: softmax weights ``A`` (4096 x heads*T, T ~ 7 prompt tokens) times a per-prompt
matrix ``U = blockdiag(V_h) @ W_out``. So after each image->token attention the image tokens
are ``x = s * (Y + D @ R) + c``: a shared matrix ``Y`` scaled per token by ``s``, a low-rank
per-prompt part (``D``: 4096 x r coefficients, ``R``: r x 256), and a shared vector ``c``.
LayerNorm keeps that form exactly (its mean and variance are computed from the factors:
``|x_c|^2 = s^2|Y_c|^2 + 2 s (Y_c R^T).D + diag(D (R R^T) D^T)``), and every linear layer
applied to the image tokens (k/v/q projections, the first transposed convolution) maps ``Y``
once per image and ``R`` per prompt, so attention logits and weighted sums are computed from
``D`` directly, never materialising per-prompt 4096x256 tensors. ``R`` itself is kept
factored as per-head prompt values (B, H, T, 16) times shared (128 x 256) weights.

Only the second transposed convolution, its GELUs and the hypernetwork dot products run per
prompt at full size, and only for the prompts that need masks (`masks`), restricted to the
part of the 64x64 grid that covers the image (the rest is padding). `masks_and_counts` also
counts the logits above the stability thresholds while laying them out (`_kernels`).

Layout: per-prompt attention weights and coefficients are kept transposed, ``(B, r, N)`` with
the 4096 image tokens contiguous, so softmaxes over the few prompt tokens run along a strided
axis of contiguous rows (fast) and low-rank products are plain batched GEMMs; shared key
matrices are stored pre-transposed and concatenated (``[Z, K_const]``) once per image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import torch
import torch.nn.functional as F
from torch import nn

from samvg.sam._kernels import scatter_logits_counts
from samvg.sam.common import LayerNorm2d
from samvg.sam.model import Sam
from samvg.sam.transformer import Attention


def _heads(x: torch.Tensor, h: int) -> torch.Tensor:
    """(..., N, h*d) -> (..., h, N, d)."""
    *lead, n, c = x.shape
    return x.reshape(*lead, n, h, c // h).transpose(-3, -2)


def _lin(x: torch.Tensor, layer: torch.nn.Linear) -> torch.Tensor:
    return F.linear(x, layer.weight, layer.bias)


def _factor(vt: torch.Tensor, m: torch.Tensor) -> torch.Tensor:
    """Rows of a factored low-rank basis: vt (B, H, T, d) and m (H*d, X) -> (B, H*T, X)."""
    b, h, t, d = vt.shape
    return torch.matmul(vt, m.view(h, d, -1)).reshape(b, h * t, -1)


def _center(x: torch.Tensor, dim: int = -1) -> torch.Tensor:
    return x - x.mean(dim, keepdim=True)


def _weighted_sum(x: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
    """``(x * w).sum`` over the low-rank axis: x (B, H, T, N) (any strides), w (B, H*T, N)
    -> (B, N). The product goes into a contiguous buffer first: torch's sum over two strided
    axes of a transposed view is several times slower than over one contiguous middle axis."""
    b, h, t, n = x.shape
    prod = torch.mul(x, w.view(b, h, t, n), out=x.new_empty((b, h, t, n)))
    return prod.view(b, h * t, n).sum(1)


def _logit_scale(att: Attention) -> float:
    """The attention's logit scale, 1 / sqrt(head dimension)."""
    return 1.0 / math.sqrt(att.internal_dim // att.num_heads)


@dataclass
class DecoderState:
    """Per-prompt results of the transformer, enough to make IoU scores and masks."""

    iou: torch.Tensor  # (B, 4) predicted IoU of all 4 mask tokens
    hyper: torch.Tensor  # (B, 4, 32) hypernetwork outputs of all 4 mask tokens
    s1: torch.Tensor  # (B, N) 1/std of the first image LayerNorm
    s2: torch.Tensor  # (B, N) 1/std of the second image LayerNorm
    d: torch.Tensor  # (B, r, N) low-rank coefficients of the image tokens, transposed
    vt1: torch.Tensor  # (B, H, T, dh) values of the first image->token attention
    vt2: torch.Tensor  # (B, H, T, dh) values of the second image->token attention

    def select(self, idx: torch.Tensor) -> DecoderState:
        return DecoderState(*(getattr(self, f)[idx] for f in self.__dataclass_fields__))


class FastDecoder:
    """Mask decoder for one image embedding, exact up to float rounding (see module doc).

    ``decode(sparse)`` matches ``MaskDecoder`` (logits for the full 256x256 grid);
    ``transformer(sparse)`` + ``masks(state, ...)`` split the work so callers can reject
    prompts by predicted IoU before computing any mask.
    """

    def __init__(self, model: Sam, image_embedding: torch.Tensor) -> None:
        if image_embedding.dim() != 4 or image_embedding.shape[0] != 1:
            raise ValueError("FastDecoder expects one image embedding (1, C, H, W)")
        self.model = model
        self._cropped_yt: tuple[tuple[int, int], torch.Tensor] | None = None
        md = model.mask_decoder
        tr = md.transformer
        if tr.depth != 2:
            raise ValueError("FastDecoder supports SAM's two-layer two-way transformer")
        self.md = md
        self.tr = tr
        with torch.inference_mode():
            self._precompute(image_embedding)

    # ------------------------------------------------------------------ shared, per image
    def _precompute(self, emb: torch.Tensor) -> None:
        tr = self.tr
        pe_enc = self.model.prompt_encoder
        l0, l1 = tr.blocks()
        fa = tr.final_attn_token_to_image
        self.h = h = l0.cross_attn_image_to_token.num_heads
        _, c, gh, gw = emb.shape
        self.grid = (gh, gw)
        e = emb[0].flatten(1).t()  # (N, C)
        s0 = e + pe_enc.no_mask_embed.weight[0]
        p = pe_enc.get_dense_pe()[0].flatten(1).t()
        self.n = s0.shape[0]

        # layer 0, token -> image: keys and values are shared
        a = l0.cross_attn_token_to_image
        self.k0 = _heads(_lin(s0 + p, a.k_proj), h)
        self.v0 = _heads(_lin(s0, a.v_proj), h)
        # layer 0, image -> token: image queries are shared
        a = l0.cross_attn_image_to_token
        q1 = _heads(_lin(s0 + p, a.q_proj), h) * _logit_scale(a)
        self.q1t = q1.transpose(1, 2).contiguous()
        wo1, bo1 = a.out_proj.weight, a.out_proj.bias  # (C, 128)
        y1c = _center(s0 + bo1)
        self.y1_sq = (y1c * y1c).sum(1)
        self.e1t = _heads(y1c @ wo1, h).transpose(1, 2).contiguous()  # (H, dh, N): Y1c . U1
        m1c = _center(wo1.t())  # (128, C) factored basis of U1, centred along C
        self.m1c = m1c
        self.gram1 = m1c @ m1c.t()  # (128, 128)
        g1, b1 = l0.norm4.weight, l0.norm4.bias
        self.eps1 = l0.norm4.eps
        yb1 = y1c * g1  # keys1 = s1 * (yb1 + A1 R1) + b1, with R1 = vt1 (m1c * g1)
        m1 = m1c * g1
        # layer 1, token -> image
        a = l1.cross_attn_token_to_image
        zk2 = _heads(F.linear(yb1, a.k_proj.weight), h)
        self.zkc2 = torch.cat([zk2, _heads(_lin(p + b1, a.k_proj), h)], 1).transpose(1, 2)
        self.zkc2 = self.zkc2.contiguous()  # (H, d, 2N): shared and constant key parts
        self.m1k = m1 @ a.k_proj.weight.t()
        self.zv2 = _heads(F.linear(yb1, a.v_proj.weight), h)
        self.vc2 = _lin(b1, a.v_proj).view(h, 1, -1)
        self.m1v = m1 @ a.v_proj.weight.t()
        # layer 1, image -> token
        a = l1.cross_attn_image_to_token
        s = _logit_scale(a)
        zq3 = _heads(F.linear(yb1, a.q_proj.weight), h) * s
        qc3 = _heads(_lin(p + b1, a.q_proj), h) * s
        self.zqc3 = torch.cat([zq3, qc3], 1).transpose(1, 2).contiguous()  # (H, d, 2N)
        self.m1q = (m1 @ a.q_proj.weight.t()) * s
        wo3, bo3 = a.out_proj.weight, a.out_proj.bias
        # second LayerNorm: x2 = s1*yb1 + (s1*A1) R1 + A2 R2 + (b1 + bo3)
        yb1c = _center(yb1)
        self.yb1c_sq = (yb1c * yb1c).sum(1)
        m1cc = _center(m1)
        m2c = _center(wo3.t())
        cc = _center(b1 + bo3)
        self.basis = torch.cat([m1cc, m2c], 0)  # (256, C): rows of R1 (first 128), R2 (last)
        self.cc = cc
        self.e2t = _heads(yb1c @ self.basis.t(), h * 2).transpose(1, 2).contiguous()
        self.y_cc = yb1c @ cc
        g2, b2 = l1.norm4.weight, l1.norm4.bias
        self.eps2 = l1.norm4.eps
        # keys2 = s2 * (s1 * yb1c*g2 + D' R'*g2) + b2 with D' = [s1 A1, A2, 1]
        y2 = yb1c * g2
        self.y2 = y2
        self.b2 = b2
        basis2 = torch.cat([self.basis, cc[None]], 0) * g2  # (257, C)
        self.basis2 = basis2
        self._precompute_output(p, fa)

    def _precompute_output(self, p: torch.Tensor, fa: Attention) -> None:
        """Shared parts of the final token->image attention and of the first transposed
        convolution, from the second LayerNorm's factors (``y2``, ``b2``, ``basis2``)."""
        h, y2, b2, basis2 = self.h, self.y2, self.b2, self.basis2
        # final token -> image attention
        zkf = _heads(F.linear(y2, fa.k_proj.weight), h)
        self.zkcf = torch.cat([zkf, _heads(_lin(p + b2, fa.k_proj), h)], 1).transpose(1, 2)
        self.zkcf = self.zkcf.contiguous()
        self.mkf = basis2 @ fa.k_proj.weight.t()  # (257, 128)
        self.zvf = _heads(F.linear(y2, fa.v_proj.weight), h)
        self.vcf = _lin(b2, fa.v_proj).view(h, 1, -1)
        self.mvf = basis2 @ fa.v_proj.weight.t()
        # output upscaling, first transposed conv as a (C, 4*C/4) matrix, columns (a, b, ch)
        up = self.md.output_upscaling  # ConvTranspose2d, LayerNorm2d, GELU, ConvTranspose2d, GELU
        conv1, conv2 = cast(nn.ConvTranspose2d, up[0]), cast(nn.ConvTranspose2d, up[3])
        assert conv1.bias is not None and conv2.bias is not None  # SAM's have biases
        w1 = conv1.weight  # (C, C/4, 2, 2)
        self.c4 = w1.shape[1]
        self.wt1 = w1.permute(0, 2, 3, 1).reshape(w1.shape[0], -1)
        self.bt1 = conv1.bias.repeat(4)
        self.ln_up = cast(LayerNorm2d, up[1])
        w2 = conv2.weight  # (C/4, C/8, 2, 2)
        self.c8 = w2.shape[1]
        self.wt2 = w2.permute(0, 2, 3, 1).reshape(w2.shape[0], -1)
        self.bt2 = conv2.bias.repeat(4)
        self.yt = y2 @ self.wt1  # (N, 4*C/4), scaled by s2*s1 per prompt
        self.ct = b2 @ self.wt1 + self.bt1
        self.mt = basis2 @ self.wt1  # (257, 4*C/4)

    # ------------------------------------------------------------------ per prompt
    def _t2i_shared(self, q: torch.Tensor, k: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
        """Token->image attention against shared keys/values: q (B, H, T, d), k/v (H, N, d)."""
        b, h, t, d = q.shape
        qh = q.transpose(0, 1).reshape(h, b * t, d) / math.sqrt(d)
        att = torch.softmax(qh @ k.transpose(1, 2), dim=-1)
        return (att @ v).view(h, b, t, d).transpose(0, 1)

    def _t2i_lowrank(
        self,
        q: torch.Tensor,
        scale: torch.Tensor,
        inner: torch.Tensor | None,
        zkc_t: torch.Tensor,
        d_t: torch.Tensor,
        r_k: torch.Tensor,
        z_v: torch.Tensor,
        r_v: torch.Tensor,
        vc: torch.Tensor,
    ) -> torch.Tensor:
        """Token->image attention on image tokens ``s*(inner*Z + D R) + const``.

        q (B, H, T, d) already scaled; scale = s (B, N); inner (B, N) or None; zkc_t
        (H, d, 2N) shared key parts ``[Z_k, K_const]`` transposed; d_t (B, r, N) = D^T;
        r_* (B, r, H*d) per prompt; z_v (H, N, d) shared; vc (H, 1, d).
        """
        b, h, t, dd = q.shape
        n = zkc_t.shape[2] // 2
        qh = q.transpose(0, 1).reshape(h, b * t, dd)
        both = torch.matmul(qh, zkc_t).view(h, b, t, 2, n)  # (H, B, T, 2, N)
        a_sh = both[:, :, :, 0].transpose(0, 1)  # (B, H, T, N) views
        a_c = both[:, :, :, 1].transpose(0, 1)
        # (B, H, T, r) = q_h . r_k,h ; logits laid out (B, H*T, N), softmax over contiguous N
        qr = torch.matmul(q, r_k.view(b, -1, h, dd).permute(0, 2, 3, 1))
        lg = torch.bmm(qr.reshape(b, h * t, -1), d_t).view(b, h, t, n)
        if inner is not None:
            lg.addcmul_(a_sh, inner[:, None, None, :])
        else:
            lg.add_(a_sh)
        lg.mul_(scale[:, None, None, :]).add_(a_c)
        att_s = torch.softmax(lg, dim=-1).mul_(scale[:, None, None, :])
        pd = torch.bmm(att_s.view(b, h * t, n), d_t.transpose(1, 2)).view(b, h, t, -1)
        w_sh = att_s * inner[:, None, None, :] if inner is not None else att_s
        o_sh = torch.matmul(w_sh.transpose(0, 1).reshape(h, b * t, n), z_v)
        o_sh = o_sh.view(h, b, t, dd).transpose(0, 1)
        o_lr = torch.matmul(pd, r_v.view(b, -1, h, dd).transpose(1, 2))
        return o_sh + o_lr + vc

    def transformer(self, sparse: torch.Tensor) -> DecoderState:
        """Run the two-way transformer for B prompts (sparse tokens (B, Ts, C))."""
        md = self.md
        l0, l1 = self.tr.blocks()
        h = self.h
        b = sparse.shape[0]
        tok = torch.cat([md.output_tokens().unsqueeze(0).expand(b, -1, -1), sparse], dim=1)
        t = tok.shape[1]
        ht = h * t
        pe = tok
        # ---- layer 0 (no PE in the self attention, its output replaces the tokens)
        q = l0.norm1(l0.self_attn(tok, tok, tok))
        a = l0.cross_attn_token_to_image
        qq = _heads(_lin(q + pe, a.q_proj), h)
        o = self._t2i_shared(qq, self.k0, self.v0)
        q = l0.norm2(q + a.out_proj(o.transpose(1, 2).reshape(b, t, -1)))
        q = l0.norm3(q + l0.mlp(q))
        a = l0.cross_attn_image_to_token
        kt = _heads(_lin(q + pe, a.k_proj), h)  # (B, H, T, d)
        vt1 = _heads(_lin(q, a.v_proj), h)
        n = self.n
        # image->token logits (H, B, T, N) (image queries shared); weights A1^T (B, HT, N)
        lg = torch.matmul(kt.transpose(0, 1).reshape(h, b * t, -1), self.q1t).view(h, b, t, n)
        a1 = torch.softmax(lg.transpose(0, 1), dim=2).reshape(b, ht, n)
        # LayerNorm statistics of x1 = Y1 + A1 U1
        cross = torch.matmul(vt1.transpose(0, 1).reshape(h, b * t, -1), self.e1t)
        cross = _weighted_sum(cross.view(h, b, t, n).transpose(0, 1), a1)
        u1 = _factor(vt1, self.m1c)  # (B, HT, C) centred rows of U1
        g = torch.bmm(u1, u1.transpose(1, 2))
        quad = torch.bmm(g, a1).mul_(a1).sum(1)
        c = self.y2.shape[1]
        var1 = (self.y1_sq + 2 * cross + quad) / c
        s1 = torch.rsqrt(var1 + self.eps1)
        # ---- layer 1
        q1 = q + pe
        q = l1.norm1(q + l1.self_attn(q1, q1, q))
        a = l1.cross_attn_token_to_image
        qq = _heads(_lin(q + pe, a.q_proj), h) / math.sqrt(a.internal_dim // h)
        o = self._t2i_lowrank(
            qq,
            s1,
            None,
            self.zkc2,
            a1,
            _factor(vt1, self.m1k),
            self.zv2,
            _factor(vt1, self.m1v),
            self.vc2,
        )
        q = l1.norm2(q + a.out_proj(o.transpose(1, 2).reshape(b, t, -1)))
        q = l1.norm3(q + l1.mlp(q))
        a = l1.cross_attn_image_to_token
        kt = _heads(_lin(q + pe, a.k_proj), h)
        vt2 = _heads(_lin(q, a.v_proj), h)
        # logits (B, H, T, N) = s1 * (Zq kt + A1 (R1q kt)) + Qc kt
        lzc = torch.matmul(kt.transpose(0, 1).reshape(h, b * t, -1), self.zqc3)
        lzc = lzc.view(h, b, t, 2, n)
        r1q = _factor(vt1, self.m1q).view(b, ht, h, -1).transpose(1, 2)  # (B, H, HT, d)
        rk = torch.matmul(r1q, kt.transpose(2, 3))  # (B, H, HT, T)
        lg = torch.bmm(rk.transpose(2, 3).reshape(b, ht, ht), a1).view(b, h, t, n)
        lg.add_(lzc[:, :, :, 0].transpose(0, 1)).mul_(s1[:, None, None, :])
        lg.add_(lzc[:, :, :, 1].transpose(0, 1))
        a2 = torch.softmax(lg, dim=2).view(b, ht, n)
        d, vt12, s2 = self._second_norm(a1, a2, s1, vt1, vt2)
        iou, hyper = self._final_attention(q, pe, vt12, d, s1, s2)
        return DecoderState(iou, hyper, s1, s2, d, vt1, vt2)

    def _second_norm(
        self,
        a1: torch.Tensor,
        a2: torch.Tensor,
        s1: torch.Tensor,
        vt1: torch.Tensor,
        vt2: torch.Tensor,
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Factors of the second image LayerNorm from both image->token attentions (weights
        a1, a2 (B, HT, N), values vt1, vt2): D'^T (B, 2HT+1, N), vt12 (B, 2H, T, d), s2 (B, N)."""
        h = self.h
        b, t = vt1.shape[0], vt1.shape[2]
        ht, n, c = h * t, self.n, self.y2.shape[1]
        # second LayerNorm: x2c = s1*Yc + D' R' with D'^T = [s1*A1; A2; 1] (B, 2HT+1, N)
        d = torch.cat([a1 * s1[:, None, :], a2, torch.ones_like(a2[:, :1])], dim=1)
        vt12 = torch.cat([vt1, vt2], dim=1)  # (B, 2H, T, d)
        cross = torch.matmul(vt12.transpose(0, 1).reshape(2 * h, b * t, -1), self.e2t)
        cross = _weighted_sum(cross.view(2 * h, b, t, n).transpose(0, 1), d[:, : 2 * ht])
        cross += self.y_cc
        r = torch.cat([_factor(vt12, self.basis), self.cc.expand(b, 1, -1)], dim=1)  # (B, 2HT+1, C)
        g = torch.bmm(r, r.transpose(1, 2))
        quad = torch.bmm(g, d).mul_(d).sum(1)
        var2 = (s1 * s1 * self.yb1c_sq + 2 * s1 * cross + quad) / c
        return d, vt12, torch.rsqrt(var2 + self.eps2)

    def _final_attention(
        self,
        q: torch.Tensor,
        pe: torch.Tensor,
        vt12: torch.Tensor,
        d: torch.Tensor,
        s1: torch.Tensor,
        s2: torch.Tensor,
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """The final token->image attention, then the IoU head and the hypernetworks on its
        tokens: (iou (B, 4), hyper (B, 4, 32))."""
        md, tr = self.md, self.tr
        fa = tr.final_attn_token_to_image
        h, b = self.h, q.shape[0]
        # only the IoU token and the mask tokens are read after the final attention
        k_out = 1 + md.num_mask_tokens
        q, pe = q[:, :k_out], pe[:, :k_out]
        qf = _heads(_lin(q + pe, fa.q_proj), h) / math.sqrt(fa.internal_dim // h)
        rkf = self._basis_rows(vt12, self.mkf)
        rvf = self._basis_rows(vt12, self.mvf)
        o = self._t2i_lowrank(qf, s2, s1, self.zkcf, d, rkf, self.zvf, rvf, self.vcf)
        q = tr.norm_final_attn(q + fa.out_proj(o.transpose(1, 2).reshape(b, k_out, -1)))
        iou = md.iou_prediction_head(q[:, 0, :])
        mt = q[:, 1 : 1 + md.num_mask_tokens, :]
        hyper = torch.stack(
            [mlp(mt[:, i, :]) for i, mlp in enumerate(md.output_hypernetworks_mlps)], dim=1
        )
        return iou, hyper

    def _basis_rows(self, vt12: torch.Tensor, m: torch.Tensor) -> torch.Tensor:
        """Rows of R' mapped by a shared matrix: m (257, X) -> (B, 2HT+1, X)."""
        b = vt12.shape[0]
        return torch.cat([_factor(vt12, m[:-1]), m[-1:].expand(b, 1, -1)], dim=1)

    def _cell_logits(
        self,
        state: DecoderState,
        mask_ids: list[int] | torch.Tensor,
        grid_hw: tuple[int, int] | None,
    ) -> torch.Tensor:
        """Mask logits per grid cell: (B, gh, gw, 2, 2, 2, 2, M), see `_kernels`."""
        gh, gw = grid_hw if grid_hw is not None else self.grid
        b = state.s1.shape[0]
        nv = gh * gw
        full = (gh, gw) == self.grid
        if full:
            d, s1, s2, yt = state.d, state.s1, state.s2, self.yt
        else:
            gy, gx = self.grid

            def crop(x: torch.Tensor) -> torch.Tensor:
                return x.reshape(*x.shape[:-1], gy, gx)[..., :gh, :gw].reshape(*x.shape[:-1], nv)

            d, s1, s2 = crop(state.d), crop(state.s1), crop(state.s2)
            if self._cropped_yt is None or self._cropped_yt[0] != (gh, gw):
                self._cropped_yt = ((gh, gw), crop(self.yt.t()).t())
            yt = self._cropped_yt[1]
        vt12 = torch.cat([state.vt1, state.vt2], dim=1)
        rt = self._basis_rows(vt12, self.mt)  # (B, r+1, 4*C4)
        x = torch.baddbmm(yt.unsqueeze(0) * s1[:, :, None], d.transpose(1, 2), rt)
        x.mul_(s2[:, :, None]).add_(self.ct)  # (B, Nv, 4*C4), first transposed conv output
        c4 = self.c4
        x = F.layer_norm(
            x.view(b, nv * 4, c4), (c4,), self.ln_up.weight, self.ln_up.bias, self.ln_up.eps
        )
        x = F.gelu(x)
        z = torch.addmm(self.bt2, x.view(-1, c4), self.wt2)  # (B*Nv*4, 4*C8)
        z = torch.ops.aten.gelu_(z).view(b, nv * 16, self.c8)
        hyper = state.hyper[:, list(mask_ids) if not torch.is_tensor(mask_ids) else mask_ids]
        m = torch.bmm(z, hyper.transpose(1, 2))  # (B, Nv*16, M)
        return m.view(b, gh, gw, 2, 2, 2, 2, m.shape[-1])

    def masks(
        self,
        state: DecoderState,
        mask_ids: list[int] | torch.Tensor,
        grid_hw: tuple[int, int] | None = None,
    ) -> torch.Tensor:
        """Low-res mask logits (B, M, 4*gh, 4*gw) of mask tokens ``mask_ids`` (0..3).

        Only the top-left ``grid_hw`` cells of the 64x64 embedding grid are upscaled (the rest
        covers padding); default: the whole grid (256x256 logits).
        """
        m = self._cell_logits(state, mask_ids, grid_hw)
        b, gh, gw, nm = m.shape[0], m.shape[1], m.shape[2], m.shape[-1]
        m = m.permute(0, 7, 1, 3, 5, 2, 4, 6)
        return m.reshape(b, nm, 4 * gh, 4 * gw)

    def masks_and_counts(
        self,
        state: DecoderState,
        mask_ids: list[int] | torch.Tensor,
        grid_hw: tuple[int, int] | None,
        valid_hw: tuple[int, int],
        hi: float,
        lo: float,
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """`masks` plus counts (B, M, 2) of logits > ``hi`` and > ``lo`` in the top-left
        ``valid_hw`` low-res pixels (for stability scores), in one pass over the logits."""
        m = self._cell_logits(state, mask_ids, grid_hw).contiguous()
        b, gh, gw, nm = m.shape[0], m.shape[1], m.shape[2], m.shape[-1]
        out = torch.empty((b, nm, 4 * gh, 4 * gw), dtype=m.dtype)
        counts = torch.empty((b, nm, 2), dtype=torch.int64)
        scatter_logits_counts(
            m.numpy(), valid_hw[0], valid_hw[1], float(hi), float(lo), out.numpy(), counts.numpy()
        )
        return out, counts

    def decode(
        self, sparse: torch.Tensor, multimask_output: bool = True
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Same outputs as ``MaskDecoder.forward`` with the no-mask dense prompt."""
        with torch.inference_mode():
            st = self.transformer(sparse)
            ids = [1, 2, 3] if multimask_output else [0]
            return self.masks(st, ids), st.iou[:, ids]
