use ctrnn::network::*;
use ctrnn::{Result, Stream};

fn net2() -> Network {
    Network::new(
        vec![1.0, 2.0],
        vec![0.0, 0.5],
        vec![1.0, 2.0, 3.0, 4.0],
        vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
        None,
    )
    .unwrap()
}

#[test]
fn shapes_are_inferred() {
    let n = net2();
    assert_eq!((n.size(), n.n_inputs()), (2, 3));
    assert_eq!(n.state(), &[0.0, 0.0]);
}

#[test]
fn validation_names_field_and_index() {
    let err = |r: Result<Network>| r.unwrap_err().to_string();
    let e = err(Network::new(
        vec![1.0, -2.0],
        vec![0.0; 2],
        vec![0.0; 4],
        vec![],
        None,
    ));
    assert!(e.contains("tau[1]") && e.contains("> 0"), "{e}");
    let e = err(Network::new(
        vec![1.0, 0.0],
        vec![0.0; 2],
        vec![0.0; 4],
        vec![],
        None,
    ));
    assert!(e.contains("tau[1]"), "{e}");
    let e = err(Network::new(
        vec![1.0; 2],
        vec![0.0; 2],
        vec![0.0, 0.0, f64::NAN, 0.0],
        vec![],
        None,
    ));
    assert!(e.contains("weights[1][0]") && e.contains("finite"), "{e}");
    let e = err(Network::new(
        vec![1.0; 2],
        vec![0.0; 3],
        vec![0.0; 4],
        vec![],
        None,
    ));
    assert!(e.contains("theta has 3 values; expected N = 2"), "{e}");
    let e = err(Network::new(
        vec![1.0; 2],
        vec![0.0; 2],
        vec![0.0; 3],
        vec![],
        None,
    ));
    assert!(e.contains("weights") && e.contains("N x N = 4"), "{e}");
    let e = err(Network::new(
        vec![1.0; 2],
        vec![0.0; 2],
        vec![0.0; 4],
        vec![0.0; 3],
        None,
    ));
    assert!(
        e.contains("sensor_weights") && e.contains("multiple"),
        "{e}"
    );
    let e = err(Network::new(vec![], vec![], vec![], vec![], None));
    assert!(e.contains("at least 1 neuron"), "{e}");
    let e = err(Network::new(
        vec![1.0; 2],
        vec![0.0; 2],
        vec![0.0; 4],
        vec![0.0, f64::INFINITY],
        None,
    ));
    assert!(e.contains("sensor_weights[1][0]"), "{e}");
    let e = err(Network::new(
        vec![1.0; 2],
        vec![0.0; 2],
        vec![0.0; 4],
        vec![],
        Some(vec![0.0]),
    ));
    assert!(e.contains("state has 1 value;"), "{e}");
}

#[test]
fn set_state_checks_and_resets() {
    let mut n = net2();
    n.set_state(Some(&[1.0, 2.0])).unwrap();
    assert_eq!(n.state(), &[1.0, 2.0]);
    assert!(n.set_state(Some(&[f64::NAN, 0.0])).is_err());
    assert!(n.set_state(Some(&[0.0])).is_err());
    n.set_state(None).unwrap();
    assert_eq!(n.state(), &[0.0, 0.0]);
}

#[test]
fn compose_places_blocks_and_zero_cross_weights() {
    let a = net2();
    let b = Network::new(vec![5.0], vec![-1.0], vec![7.0], vec![8.0, 9.0, 10.0], None).unwrap();
    let ab = compose(&a, &b).unwrap();
    assert_eq!(ab.size(), 3);
    assert_eq!(ab.tau(), &[1.0, 2.0, 5.0]);
    assert_eq!(ab.weights(), &[1.0, 2.0, 0.0, 3.0, 4.0, 0.0, 0.0, 0.0, 7.0]);
    assert_eq!(&ab.sensor_weights()[6..], &[8.0, 9.0, 10.0]);
    let c = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    assert!(compose(&a, &c).unwrap_err().to_string().contains("same M"));
}

#[test]
fn compose_with_draws_only_the_cross_weights() {
    use ctrnn::rng::Purpose;
    let a = net2();
    let b = Network::new(vec![5.0], vec![-1.0], vec![7.0], vec![8.0, 9.0, 10.0], None).unwrap();
    let stream = || Stream::new(3, 0, Purpose::Seeding, 0, 1);
    let ab = compose_with(&a, &b, 2.0, &mut stream()).unwrap();
    let w = ab.weights();
    // a's block and b's block are unchanged; the four cross weights are in [-2, 2], not 0.
    assert_eq!((w[0], w[1], w[3], w[4], w[8]), (1.0, 2.0, 3.0, 4.0, 7.0));
    let cross = [w[2], w[5], w[6], w[7]];
    assert!(
        cross.iter().all(|x| *x != 0.0 && x.abs() <= 2.0),
        "{cross:?}"
    );
    // drawn in row-major order from the stream
    let mut s = stream();
    let expected: Vec<f64> = (0..4).map(|_| s.range(-2.0, 2.0)).collect();
    assert_eq!(cross.to_vec(), expected);
    // scale 0 is compose; a bad scale is an error
    assert_eq!(
        compose_with(&a, &b, 0.0, &mut stream()).unwrap(),
        compose(&a, &b).unwrap()
    );
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let e = compose_with(&a, &b, bad, &mut stream()).unwrap_err();
        assert!(e.to_string().contains("cross_scale is"), "{e}");
    }
}
