use ctrnn::validation::*;

#[test]
fn candidates_are_the_best_by_fitness_then_index() {
    let f = [0.5, 0.7, 0.7, 0.1, 0.9];
    assert_eq!(candidates(&f, 3), vec![4, 1, 2]);
    assert_eq!(candidates(&f, 0), Vec::<usize>::new());
    assert_eq!(candidates(&f, 10), vec![4, 1, 2, 0, 3]);
}

#[test]
fn beats_is_lexicographic_and_strict() {
    let v = |rate, score| Validation { rate, score };
    assert!(v(0.9, 0.1).beats(&v(0.8, 0.9)));
    assert!(v(0.9, 0.5).beats(&v(0.9, 0.4)));
    assert!(!v(0.9, 0.5).beats(&v(0.9, 0.5)));
    assert!(!v(0.8, 1.0).beats(&v(0.9, 0.0)));
}
