//! Dense arrays in numpy's C order, as pymdp stores `A[m]`, `B[f]`, `C[m]`, `pA`, `pB`,
//! and the one contraction every algorithm needs (pymdp's `factor_dot`).

use super::error::ModelError;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::Value;

/// A dense array of f64: `shape` and the entries in C (row-major) order.
#[derive(Debug, Clone, PartialEq)]
pub struct Tensor {
    /// Length of each axis.
    pub shape: Vec<usize>,
    /// Entries, the last axis varying fastest.
    pub data: Vec<f64>,
}

impl Tensor {
    /// An array of the given shape filled with `value`.
    pub fn filled(shape: Vec<usize>, value: f64) -> Tensor {
        let n = shape.iter().product();
        Tensor {
            shape,
            data: vec![value; n],
        }
    }

    /// Number of axes.
    pub fn ndim(&self) -> usize {
        self.shape.len()
    }

    /// Strides in entries, C order.
    pub fn strides(&self) -> Vec<usize> {
        strides(&self.shape)
    }

    /// Read a nested JSON array (numbers at the leaves, every level rectangular).
    /// `name` is the array's name in errors, e.g. `"A[1]"`.
    pub fn from_json(name: &str, v: &Value) -> Result<Tensor, ModelError> {
        let mut shape = Vec::new();
        let mut cur = v;
        while let Value::Array(items) = cur {
            shape.push(items.len());
            match items.first() {
                Some(first) => cur = first,
                None => break,
            }
        }
        let mut data = Vec::with_capacity(shape.iter().product());
        collect(name, v, &shape, &mut Vec::new(), &mut data)?;
        Ok(Tensor { shape, data })
    }

    /// The nested JSON array of this tensor.
    pub fn to_json(&self) -> Value {
        fn build(shape: &[usize], data: &[f64]) -> Value {
            match shape.split_first() {
                None => serde_json::json!(data[0]),
                Some((&n, rest)) => {
                    let step: usize = rest.iter().product();
                    Value::Array((0..n).map(|i| build(rest, &data[i * step..(i + 1) * step])).collect())
                }
            }
        }
        build(&self.shape, &self.data)
    }

    /// The sub-array at `index` on the last axis (pymdp's `B[f][..., u]`).
    pub fn slice_last(&self, index: usize) -> Tensor {
        let (&n, rest) = self.shape.split_last().expect("a tensor with at least one axis");
        let data = self.data.iter().skip(index).step_by(n).copied().collect();
        Tensor {
            shape: rest.to_vec(),
            data,
        }
    }

    /// The sub-array at `index` on the first axis (pymdp's `A[m][o]`).
    pub fn slice_first(&self, index: usize) -> Tensor {
        let rest = self.shape[1..].to_vec();
        let step: usize = rest.iter().product();
        Tensor {
            shape: rest,
            data: self.data[index * step..(index + 1) * step].to_vec(),
        }
    }
}

/// C-order strides of `shape`.
pub fn strides(shape: &[usize]) -> Vec<usize> {
    let mut s = vec![1; shape.len()];
    for k in (0..shape.len().saturating_sub(1)).rev() {
        s[k] = s[k + 1] * shape[k + 1];
    }
    s
}

fn collect(name: &str, v: &Value, shape: &[usize], at: &mut Vec<usize>, out: &mut Vec<f64>) -> Result<(), ModelError> {
    let depth = at.len();
    match v {
        Value::Array(items) => {
            if depth >= shape.len() || items.len() != shape[depth] {
                return Err(ModelError::Ragged {
                    array: name.to_string(),
                    place: place(name, at),
                    found: items.len(),
                    expected: shape.get(depth).copied(),
                });
            }
            for (i, item) in items.iter().enumerate() {
                at.push(i);
                collect(name, item, shape, at, out)?;
                at.pop();
            }
            Ok(())
        }
        Value::Number(n) if depth == shape.len() => {
            out.push(n.as_f64().unwrap_or(f64::NAN));
            Ok(())
        }
        Value::Number(_) => Err(ModelError::Ragged {
            array: name.to_string(),
            place: place(name, at),
            found: 0,
            expected: Some(shape[depth]),
        }),
        other => Err(ModelError::NotANumber {
            array: name.to_string(),
            place: place(name, at),
            found: other.to_string(),
        }),
    }
}

fn place(name: &str, at: &[usize]) -> String {
    let mut s = name.to_string();
    for i in at {
        s.push_str(&format!("[{i}]"));
    }
    s
}

impl Serialize for Tensor {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(s)
    }
}

impl<'de> Deserialize<'de> for Tensor {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Tensor, D::Error> {
        let v = Value::deserialize(d)?;
        Tensor::from_json("array", &v).map_err(serde::de::Error::custom)
    }
}

/// `Σ_{all axes but keep} t[i_0, i_1, ...] · Π_k xs[k][i_k]`: contract every axis of `t`
/// except `keep` with one vector each (`xs[k]` for axis k; `xs[keep]` is ignored). With
/// `keep = None` the result has one entry (a full contraction). pymdp's `factor_dot`.
pub fn contract(t: &Tensor, xs: &[&[f64]], keep: Option<usize>) -> Vec<f64> {
    let nd = t.ndim();
    debug_assert_eq!(xs.len(), nd);
    let out_len = keep.map_or(1, |k| t.shape[k]);
    let mut out = vec![0.0; out_len];
    if nd == 0 {
        out[0] = t.data[0];
        return out;
    }
    // Contract the last axis first, then the next, ... (one pass per axis), which keeps
    // every step a plain weighted sum over contiguous rows.
    let mut cur: std::borrow::Cow<[f64]> = std::borrow::Cow::Borrowed(&t.data);
    let mut shape = t.shape.clone();
    for axis in (0..nd).rev() {
        if Some(axis) == keep {
            continue;
        }
        let n = shape[axis];
        let inner: usize = shape[axis + 1..].iter().product();
        let outer: usize = shape[..axis].iter().product();
        let x = xs[axis];
        let mut next = vec![0.0; outer * inner];
        if inner == 1 {
            for (o, d) in next.iter_mut().enumerate() {
                *d = cur[o * n..(o + 1) * n].iter().zip(x).map(|(r, xi)| r * xi).sum();
            }
        } else {
            for o in 0..outer {
                let dst = &mut next[o * inner..(o + 1) * inner];
                for (i, xi) in x.iter().enumerate().take(n) {
                    let row = &cur[(o * n + i) * inner..(o * n + i + 1) * inner];
                    for (d, r) in dst.iter_mut().zip(row) {
                        *d += r * xi;
                    }
                }
            }
        }
        cur = std::borrow::Cow::Owned(next);
        shape.remove(axis);
    }
    out.copy_from_slice(&cur);
    out
}

/// Outer product `⊗_k xs[k]` in C order (pymdp's `multidimensional_outer`).
pub fn outer(xs: &[&[f64]]) -> Vec<f64> {
    let mut cur = vec![1.0];
    for x in xs {
        let mut next = Vec::with_capacity(cur.len() * x.len());
        for c in &cur {
            next.extend(x.iter().map(|v| c * v));
        }
        cur = next;
    }
    cur
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_round_trip_and_ragged_refused() {
        let v: Value = serde_json::from_str("[[[1,2],[3,4],[5,6]]]").unwrap();
        let t = Tensor::from_json("A[0]", &v).unwrap();
        assert_eq!(t.shape, vec![1, 3, 2]);
        assert_eq!(t.data, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(Tensor::from_json("A[0]", &t.to_json()).unwrap(), t);
        let bad: Value = serde_json::from_str("[[1,2],[3]]").unwrap();
        let e = Tensor::from_json("B[1]", &bad).unwrap_err().to_string();
        assert!(
            e.contains("B[1][1]") && e.contains("1 entries") && e.contains("2"),
            "{e}"
        );
        let bad: Value = serde_json::from_str("[[1,\"x\"]]").unwrap();
        assert!(
            Tensor::from_json("C[0]", &bad)
                .unwrap_err()
                .to_string()
                .contains("C[0][0][1]")
        );
    }

    #[test]
    fn contract_matches_the_explicit_sum() {
        let t = Tensor {
            shape: vec![2, 3, 2],
            data: (0..12).map(|i| i as f64 * 0.5 - 1.0).collect(),
        };
        let x0 = [0.3, 0.7];
        let x1 = [0.2, 0.5, 0.3];
        let x2 = [0.6, 0.4];
        let full = contract(&t, &[&x0, &x1, &x2], None)[0];
        let keep1 = contract(&t, &[&x0, &x1, &x2], Some(1));
        let mut want = 0.0;
        let mut want1 = [0.0; 3];
        for (n, v) in t.data.iter().enumerate() {
            let (i, j, k) = (n / 6, (n / 2) % 3, n % 2);
            want += v * x0[i] * x1[j] * x2[k];
            want1[j] += v * x0[i] * x2[k];
        }
        assert!((full - want).abs() < 1e-12);
        for (a, b) in keep1.iter().zip(want1) {
            assert!((a - b).abs() < 1e-12);
        }
        assert_eq!(t.slice_last(1).data, vec![-0.5, 0.5, 1.5, 2.5, 3.5, 4.5]);
        assert_eq!(outer(&[&[1.0, 2.0], &[3.0, 4.0]]), vec![3.0, 4.0, 6.0, 8.0]);
    }
}
