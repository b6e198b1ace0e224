use super::*;

const L: usize = 16;

fn basis() -> [f64; L] {
    core::array::from_fn(|i| 0.1 + 0.05 * i as f64)
}

/// A buffer and its layout for N = 1, L = 16.
fn buffer() -> (Vec<f64>, Layout) {
    let len = Layout::buffer_len(1, L).unwrap();
    let buf = vec![0.0; len];
    let layout = Layout::new(1, L, buf.as_ptr() as usize, len).unwrap();
    (buf, layout)
}

#[test]
fn layout_aligns_rows_and_keeps_the_gap() {
    let (buf, layout) = buffer();
    let (s, w) = layout.split(&buf);
    assert_eq!(s.len(), L);
    assert_eq!(w.len(), 3 * 16);
    assert_eq!(s.as_ptr() as usize % 64, 0);
    assert_eq!(w.as_ptr() as usize % 64, 0);
    assert_eq!(w.as_ptr() as usize - s.as_ptr() as usize, 8 * (16 + GAP));
    assert!(Layout::new(1, L, 0, Layout::buffer_len(1, L).unwrap() - 1).is_none());
    assert_eq!(Layout::buffer_len(7, usize::MAX), None);
}

#[test]
fn fused_step_equals_output_then_euler_update() {
    let (mut buf, layout) = buffer();
    let (_, rows) = layout.split_mut(&mut buf);
    let mut w = WeightsMut::<1>::new(rows, L, layout.stride);
    // Some non-zero weights.
    for (i, v) in w.d_mut(0, 0).iter_mut().enumerate() {
        *v = 0.01 * i as f64;
    }
    w.c_mut(0, 0).fill(-0.2);
    w.g_mut(0).fill(0.3);
    let s = basis();
    let (da, a, z2) = (
        Vector::<1>::new(2.0),
        Vector::<1>::new(-0.5),
        Vector::<1>::new(0.1),
    );
    let ts = 1e-3;
    let (gamma, sigma) = ([100.0; 3], [0.01; 3]);
    let rates = Rates::new(ts, gamma, sigma).unwrap();
    let expect_out = w.as_ref().output(SimdPath::portable(), &s, &da, &a);
    let expect_norms = w.as_ref().norms();
    // The SPEC's form: Ŵ ← Ŵ + Ts Γ (S u z2 − σ Ŵ).
    let old: Vec<Vec<f64>> = (0..3).map(|i| w.as_ref().row(i).to_vec()).collect();
    let u = [da[0], a[0], 1.0];
    let mut copy: Vec<f64> = (0..3).flat_map(|i| w.as_ref().row(i).to_vec()).collect();
    let mut w2 = WeightsMut::<1>::new(&mut copy, L, L);
    let mut norms = expect_norms;
    let out = w.fused_step(SimdPath::fastest(), &s, &da, &a, &z2, &rates, &mut norms);
    // The separate update does the same.
    let new_norms = w2.update(SimdPath::fastest(), &s, &da, &a, &z2, &rates);
    for i in 0..3 {
        assert_eq!(w2.as_ref().row(i), w.as_ref().row(i));
        for n in 0..L {
            let expect = old[i][n] + ts * gamma[i] * (s[n] * u[i] * z2[0] - sigma[i] * old[i][n]);
            assert!((w.as_ref().row(i)[n] - expect).abs() < 1e-15);
        }
    }
    assert!((out - expect_out).norm() < 1e-14, "{out} vs {expect_out}");
    // The norms were brought up to date without a second pass.
    let exact = w.as_ref().norms();
    for n in 0..3 {
        assert!(
            (norms[n] - exact[n]).abs() < 1e-13 * exact[n],
            "{norms:?} vs {exact:?}"
        );
        assert!((new_norms[n] - exact[n]).abs() < 1e-13 * exact[n]);
    }
}

#[test]
fn from_rows_checks_the_length() {
    let data = [0.0; 3 * L];
    assert!(Weights::<1>::from_rows(&data, L).is_ok());
    let e = Weights::<1>::from_rows(&data[1..], L).unwrap_err();
    assert!(e.to_string().contains("(2n² + n)·L"), "{e}");
}

#[test]
fn rates_reject_nonpositive_gain_by_name() {
    let e = Rates::new(1e-3, [100.0, 0.0, 100.0], [0.01; 3]).unwrap_err();
    assert!(e.to_string().contains("Γ > 0"), "{e}");
    let e = Rates::new(1e-3, [100.0; 3], [0.01, 0.01, -1.0]).unwrap_err();
    assert!(e.to_string().contains("σ > 0"), "{e}");
}
