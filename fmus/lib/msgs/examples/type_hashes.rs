//! Prints every known message type's REP 2011 hash as one JSON object
//! (`{"pkg/msg/Type": "RIHS01_...", ...}`), for tests/test_type_hash.py to compare with an
//! independent implementation.

fn main() {
    let mut out = String::from("{");
    for (i, (name, hash)) in agrisim_msgs::type_hashes().iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        out.push_str(&format!("\"{name}\": \"{hash}\""));
    }
    out.push('}');
    println!("{out}");
}
